//! Start and goal markers with their pair numbers.

use super::MapTransform;
use crate::RenderError;
use crate::draw::{Anchor, disc, rect, ring, text, text_size};
use crate::palette;
use image::{Rgb, RgbImage};
use verti_world::World;

/// Start discs (green), goal rings (red) and pair numbers. Starts and goals share places on
/// the task circle (goal k is start k+5), so a start's number sits on one side of the
/// start-to-goal line and a goal's on the other.
pub(super) fn draw_markers(
    img: &mut RgbImage,
    world: &World,
    map: &MapTransform,
    ppc: f64,
    selected: &dyn Fn(u32) -> bool,
    numbers: bool,
) -> Result<(), RenderError> {
    let r = (1.6 * ppc).max(3.0);
    let ring_r = r + (0.6 * ppc).max(2.0);
    let ring_w = (0.55 * ppc).max(1.5);
    let fs = (2.6 * ppc).clamp(9.0, 22.0);
    let tasks: Vec<_> = world.tasks.iter().filter(|t| selected(t.pair)).collect();
    for t in &tasks {
        let (gx, gy) = map.to_pixel(t.goal[0], t.goal[1]);
        ring(img, gx, gy, ring_r, ring_w + 1.5, palette::WHITE);
        ring(img, gx, gy, ring_r, ring_w, palette::GOAL);
    }
    for t in &tasks {
        let (sx, sy) = map.to_pixel(t.start[0], t.start[1]);
        disc(img, sx, sy, r + 1.0, palette::WHITE);
        disc(img, sx, sy, r, palette::START);
    }
    if !numbers {
        // Thumbnails have no room for numbers.
        return Ok(());
    }
    let (x0, y0) = map.origin;
    let s = map.size_px();
    for t in &tasks {
        let (sx, sy) = map.to_pixel(t.start[0], t.start[1]);
        let (gx, gy) = map.to_pixel(t.goal[0], t.goal[1]);
        let (dx, dy) = (gx - sx, gy - sy);
        let len = dx.hypot(dy);
        // Unit vector from start to goal (east when they coincide).
        let (ux, uy) = if len > 1e-9 {
            (dx / len, dy / len)
        } else {
            (1.0, 0.0)
        };
        let turn = 40f64.to_radians();
        let rot = |x: f64, y: f64, a: f64| (x * a.cos() - y * a.sin(), x * a.sin() + y * a.cos());
        let label = t.pair.to_string();
        let (tw, th) = text_size(&label, fs)?;
        let dist = ring_r + ring_w + 0.5 * f64::from(tw.max(th)) + 3.0;
        for (anchor, dir, colour) in [
            ((sx, sy), rot(-ux, -uy, turn), Rgb([0x0E, 0x6E, 0x24])),
            ((gx, gy), rot(ux, uy, -turn), Rgb([0xB0, 0x10, 0x10])),
        ] {
            let hw = 0.5 * f64::from(tw) + 2.5;
            let hh = 0.5 * f64::from(th) + 1.5;
            let lx = (anchor.0 + dir.0 * dist).clamp(x0 + hw + 1.0, x0 + s - hw - 1.0);
            let ly = (anchor.1 + dir.1 * dist).clamp(y0 + hh + 1.0, y0 + s - hh - 1.0);
            rect(
                img,
                lx - hw,
                ly - hh,
                lx + hw,
                ly + hh,
                palette::WHITE,
                0.85,
            );
            text(img, &label, lx, ly, fs, colour, Anchor::CENTER)?;
        }
    }
    Ok(())
}
