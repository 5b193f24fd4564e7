//! Raster primitives on an RGB image: anti-aliased discs, rings, thick polylines and arbitrary
//! shapes given by a signed distance, plus text through `plotters`.
//!
//! Every primitive clips to the image and ignores non-finite coordinates, so callers can pass
//! anything a valid world produces (points off the map included) without checks.

use crate::RenderError;
use crate::glyphs;
use image::{ImageFormat, Rgb, RgbImage};
use plotters::backend::{BitMapBackend, RGBPixel};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;
use std::sync::OnceLock;

/// Font family name the vendored font is registered under.
pub(crate) const FONT: &str = "sans-serif";
static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the vendored font once; `plotters` built with `ab_glyph` has no other fonts.
pub(crate) fn ensure_font() -> Result<(), RenderError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, DEJAVU_SANS).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(RenderError::Draw(
            "the vendored DejaVu Sans font could not be loaded".into(),
        ))
    }
}

/// Writes an image as PNG. The path must end in `.png` and its directory must exist: a file
/// named `.jpg` holding PNG bytes, or a directory tree grown from a typo, helps no one.
pub fn save_png(image: &RgbImage, path: &Path) -> Result<(), RenderError> {
    verti_core::output::check_output_file(path, verti_core::output::IMAGE_FORMATS).map_err(
        |problem| RenderError::Output {
            path: path.to_path_buf(),
            problem,
        },
    )?;
    image
        .save_with_format(path, ImageFormat::Png)
        .map_err(|source| RenderError::Write {
            path: path.to_path_buf(),
            source,
        })
}

/// Blends colour `c` with opacity `a` (0..1) into pixel (x, y); off-image pixels are ignored.
#[inline]
pub(crate) fn blend(img: &mut RgbImage, x: i64, y: i64, c: Rgb<u8>, a: f64) {
    if x < 0 || y < 0 || x >= i64::from(img.width()) || y >= i64::from(img.height()) || a <= 0.0 {
        return;
    }
    let a = a.min(1.0);
    let p = img.get_pixel_mut(x as u32, y as u32);
    for k in 0..3 {
        p[k] = (f64::from(p[k]) * (1.0 - a) + f64::from(c[k]) * a).round() as u8;
    }
}

/// Pixel index range covering [lo, hi] clipped to [0, max).
fn span(lo: f64, hi: f64, max: u32) -> Option<(i64, i64)> {
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let a = lo.floor().max(0.0);
    let b = hi.ceil().min(f64::from(max) - 1.0);
    (a <= b).then_some((a as i64, b as i64))
}

/// Fills the shape whose signed distance (pixels, negative inside) at a pixel centre is
/// `sd(x, y)`, within the box [x0, x1] x [y0, y1]; edges get one pixel of anti-aliasing.
pub(crate) fn fill_sdf(
    img: &mut RgbImage,
    bbox: [f64; 4],
    c: Rgb<u8>,
    alpha: f64,
    sd: impl Fn(f64, f64) -> f64,
) {
    let (Some((x0, x1)), Some((y0, y1))) = (
        span(bbox[0], bbox[1], img.width()),
        span(bbox[2], bbox[3], img.height()),
    ) else {
        return;
    };
    for y in y0..=y1 {
        for x in x0..=x1 {
            let d = sd(x as f64 + 0.5, y as f64 + 0.5);
            let cover = (0.5 - d).clamp(0.0, 1.0);
            if cover > 0.0 {
                blend(img, x, y, c, cover * alpha);
            }
        }
    }
}

/// Filled disc.
pub(crate) fn disc(img: &mut RgbImage, cx: f64, cy: f64, r: f64, c: Rgb<u8>) {
    fill_sdf(
        img,
        [cx - r - 1.0, cx + r + 1.0, cy - r - 1.0, cy + r + 1.0],
        c,
        1.0,
        |x, y| (x - cx).hypot(y - cy) - r,
    );
}

/// Circle outline of radius `r` (centre of the stroke) and stroke `width`.
pub(crate) fn ring(img: &mut RgbImage, cx: f64, cy: f64, r: f64, width: f64, c: Rgb<u8>) {
    let o = r + width;
    fill_sdf(img, [cx - o, cx + o, cy - o, cy + o], c, 1.0, |x, y| {
        ((x - cx).hypot(y - cy) - r).abs() - 0.5 * width
    });
}

/// Axis-aligned filled rectangle with opacity.
pub(crate) fn rect(img: &mut RgbImage, x0: f64, y0: f64, x1: f64, y1: f64, c: Rgb<u8>, alpha: f64) {
    let (cx, cy, hx, hy) = (
        0.5 * (x0 + x1),
        0.5 * (y0 + y1),
        0.5 * (x1 - x0).abs(),
        0.5 * (y1 - y0).abs(),
    );
    fill_sdf(
        img,
        [cx - hx - 1.0, cx + hx + 1.0, cy - hy - 1.0, cy + hy + 1.0],
        c,
        alpha,
        |x, y| ((x - cx).abs() - hx).max((y - cy).abs() - hy),
    );
}

/// Distance from p to segment ab.
#[inline]
fn segment_distance(px: f64, py: f64, a: (f64, f64), b: (f64, f64)) -> f64 {
    let (ex, ey) = (b.0 - a.0, b.1 - a.1);
    let len2 = ex * ex + ey * ey;
    let t = if len2 > 0.0 {
        (((px - a.0) * ex + (py - a.1) * ey) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (px - a.0 - t * ex).hypot(py - a.1 - t * ey)
}

/// Thick polyline with round joins and caps; segment i (from point i to i+1) takes
/// `colors[i]` (the last colour repeats when there are fewer). Coverage is accumulated per
/// pixel before blending, so joins are not blended twice; where segments overlap, the later one
/// is on top. A single point draws a dot.
pub(crate) fn polyline(img: &mut RgbImage, pts: &[(f64, f64)], colors: &[Rgb<u8>], width: f64) {
    let pts: Vec<(f64, f64)> = pts
        .iter()
        .copied()
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    if pts.is_empty() || colors.is_empty() || width.is_nan() || width <= 0.0 {
        return;
    }
    let h = 0.5 * width + 1.0;
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in &pts {
        x0 = x0.min(p.0 - h);
        x1 = x1.max(p.0 + h);
        y0 = y0.min(p.1 - h);
        y1 = y1.max(p.1 + h);
    }
    let (Some((bx0, bx1)), Some((by0, by1))) =
        (span(x0, x1, img.width()), span(y0, y1, img.height()))
    else {
        return;
    };
    let bw = (bx1 - bx0 + 1) as usize;
    let mut cover = vec![(0.0f64, 0usize); bw * (by1 - by0 + 1) as usize];
    let segments: Vec<((f64, f64), (f64, f64))> = if pts.len() == 1 {
        vec![(pts[0], pts[0])]
    } else {
        pts.windows(2).map(|w| (w[0], w[1])).collect()
    };
    for (i, &(a, b)) in segments.iter().enumerate() {
        let Some((sx0, sx1)) = span(a.0.min(b.0) - h, a.0.max(b.0) + h, img.width()) else {
            continue;
        };
        let Some((sy0, sy1)) = span(a.1.min(b.1) - h, a.1.max(b.1) + h, img.height()) else {
            continue;
        };
        for y in sy0.max(by0)..=sy1.min(by1) {
            for x in sx0.max(bx0)..=sx1.min(bx1) {
                let d = segment_distance(x as f64 + 0.5, y as f64 + 0.5, a, b);
                let c = (0.5 * width + 0.5 - d).clamp(0.0, 1.0);
                let slot = &mut cover[(y - by0) as usize * bw + (x - bx0) as usize];
                if c > 0.0 && c >= slot.0 {
                    *slot = (c, i.min(colors.len() - 1));
                }
            }
        }
    }
    for (k, &(c, i)) in cover.iter().enumerate() {
        if c > 0.0 {
            blend(
                img,
                bx0 + (k % bw) as i64,
                by0 + (k / bw) as i64,
                colors[i],
                c,
            );
        }
    }
}

/// Horizontal and vertical anchoring of a text.
#[derive(Clone, Copy)]
pub(crate) struct Anchor(pub HPos, pub VPos);

impl Anchor {
    pub const LEFT: Anchor = Anchor(HPos::Left, VPos::Center);
    pub const CENTER: Anchor = Anchor(HPos::Center, VPos::Center);
}

/// Pixel advance of every character of `s` and the left bearing of its glyph at font size
/// `size`, from the font's own metrics (see `glyphs`).
fn layout(s: &str, size: f64) -> Result<Vec<(char, f64, f64)>, RenderError> {
    let m = glyphs::metrics(DEJAVU_SANS)
        .ok_or_else(|| RenderError::Draw("the vendored font has no usable metrics".into()))?;
    let k = size / m.height;
    Ok(s.chars()
        .map(|c| {
            let g = m.glyph(c);
            (c, g.advance * k, g.lsb * k)
        })
        .collect())
}

/// Size (width, height) in pixels of `s` at font size `size`.
pub(crate) fn text_size(s: &str, size: f64) -> Result<(u32, u32), RenderError> {
    ensure_font()?;
    let w: f64 = layout(s, size)?.iter().map(|g| g.1).sum();
    // Same line height as plotters' layout estimate.
    Ok((w.ceil() as u32, (size / 1.24) as u32))
}

/// Draws `s` anchored at (x, y): glyph by glyph, each at its pen position plus its left side
/// bearing (which `plotters` would drop).
pub(crate) fn text(
    img: &mut RgbImage,
    s: &str,
    x: f64,
    y: f64,
    size: f64,
    c: Rgb<u8>,
    anchor: Anchor,
) -> Result<(), RenderError> {
    ensure_font()?;
    if !(x.is_finite() && y.is_finite()) {
        return Ok(());
    }
    let glyphs = layout(s, size)?;
    let width: f64 = glyphs.iter().map(|g| g.1).sum();
    let mut pen = match anchor.0 {
        HPos::Left => x,
        HPos::Center => x - 0.5 * width,
        HPos::Right => x - width,
    };
    let (w, h) = img.dimensions();
    let backend = BitMapBackend::<RGBPixel>::with_buffer_and_format(img.as_mut(), (w, h))
        .map_err(|e| RenderError::Draw(e.to_string()))?;
    let root = backend.into_drawing_area();
    let color = RGBColor(c[0], c[1], c[2]);
    let style = TextStyle::from((FONT, size).into_font())
        .color(&color)
        .pos(Pos::new(HPos::Left, anchor.1));
    let mut buf = [0u8; 4];
    for (ch, advance, lsb) in glyphs {
        if !ch.is_whitespace() {
            let at = (
                (pen + lsb.floor()).round().clamp(-1e6, 1e6) as i32,
                y.round().clamp(-1e6, 1e6) as i32,
            );
            root.draw(&Text::new(&*ch.encode_utf8(&mut buf), at, style.clone()))
                .map_err(|e| RenderError::Draw(e.to_string()))?;
        }
        pen += advance;
    }
    root.present().map_err(|e| RenderError::Draw(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disc_and_polyline_cover_what_they_should() {
        let mut img = RgbImage::from_pixel(40, 40, Rgb([255, 255, 255]));
        disc(&mut img, 10.0, 10.0, 4.0, Rgb([0, 0, 0]));
        assert_eq!(img.get_pixel(10, 10), &Rgb([0, 0, 0]));
        assert_eq!(img.get_pixel(16, 10), &Rgb([255, 255, 255]));
        polyline(
            &mut img,
            &[(20.0, 30.5), (39.0, 30.5)],
            &[Rgb([255, 0, 0])],
            3.0,
        );
        assert_eq!(img.get_pixel(30, 30), &Rgb([255, 0, 0]));
        assert_eq!(img.get_pixel(30, 34), &Rgb([255, 255, 255]));
        // off-image and non-finite input is ignored, not a panic
        disc(&mut img, -1e300, f64::NAN, 5.0, Rgb([0, 0, 0]));
        polyline(
            &mut img,
            &[(f64::INFINITY, 0.0), (-1e9, 1e9)],
            &[Rgb([0, 0, 0])],
            2.0,
        );
        rect(&mut img, 1e12, 1e12, 2e12, 2e12, Rgb([0, 0, 0]), 1.0);
    }

    #[test]
    fn text_draws_dark_pixels() {
        let mut img = RgbImage::from_pixel(80, 30, Rgb([255, 255, 255]));
        text(
            &mut img,
            "Mud 7",
            5.0,
            15.0,
            16.0,
            Rgb([0, 0, 0]),
            Anchor::LEFT,
        )
        .unwrap();
        assert!(img.pixels().any(|p| p[0] < 100), "no glyph pixels");
        let (w, h) = text_size("Mud 7", 16.0).unwrap();
        assert!(w > 20 && h > 5);
    }
}
