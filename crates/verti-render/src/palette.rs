//! Colours: one per terrain class, the marker and path colours, and the speed colour map.

use image::Rgb;
use verti_world::TerrainClass;

/// Base colour of a terrain class before hill shading. Chosen to be told apart at a glance and
/// to echo the material: the three soils stand out (snow near white-blue, mud dark brown, sand
/// tan) from the rigid classes.
pub fn class_color(class: TerrainClass) -> Rgb<u8> {
    Rgb(match class {
        TerrainClass::Clay => [0xC8, 0x74, 0x5A],     // terracotta
        TerrainClass::Concrete => [0xBE, 0xBE, 0xBA], // light grey
        TerrainClass::Dirt => [0x96, 0x78, 0x50],     // earth brown
        TerrainClass::Grass => [0x6D, 0xAA, 0x45],    // green
        TerrainClass::Gravel => [0x7C, 0x8C, 0xA0],   // blue-grey
        TerrainClass::Rock => [0xA4, 0x8C, 0xB4],     // slate lavender
        TerrainClass::Wood => [0xD4, 0x9A, 0x30],     // amber
        TerrainClass::Mud => [0x62, 0x46, 0x30],      // dark brown
        TerrainClass::Sand => [0xE8, 0xD4, 0x98],     // tan
        TerrainClass::Snow => [0xEC, 0xF4, 0xFF],     // white-blue
    })
}

/// Fill of rocks (near black, like the paper's Fig. 4).
pub const ROCK: Rgb<u8> = Rgb([0x22, 0x22, 0x22]);
/// Fill of trees (very dark green, still reads as "obstacle").
pub const TREE: Rgb<u8> = Rgb([0x12, 0x3A, 0x16]);
/// Start markers.
pub const START: Rgb<u8> = Rgb([0x1E, 0xB4, 0x3C]);
/// Goal markers.
pub const GOAL: Rgb<u8> = Rgb([0xE0, 0x1E, 0x1E]);
/// Global paths.
pub const PATH: Rgb<u8> = Rgb([0xE8, 0x10, 0x10]);
/// Text and outlines.
pub const INK: Rgb<u8> = Rgb([0x18, 0x18, 0x18]);
pub const WHITE: Rgb<u8> = Rgb([0xFF, 0xFF, 0xFF]);
/// Background around the map.
pub const PAPER: Rgb<u8> = Rgb([0xFA, 0xFA, 0xF7]);
/// Trajectory points whose value is not a finite number.
pub const NO_VALUE: Rgb<u8> = Rgb([0x80, 0x80, 0x80]);

/// "Plasma"-like colour map stops (dark purple -> magenta -> orange -> yellow): bright and
/// saturated, so a trajectory stands out on the earthy terrain colours.
const PLASMA: [[u8; 3]; 9] = [
    [0x0D, 0x08, 0x87],
    [0x4C, 0x02, 0xA1],
    [0x7E, 0x03, 0xA8],
    [0xA9, 0x23, 0x95],
    [0xCC, 0x47, 0x78],
    [0xE5, 0x6B, 0x5D],
    [0xF8, 0x94, 0x41],
    [0xFD, 0xC3, 0x28],
    [0xF0, 0xF9, 0x21],
];

/// Colour of `t` in [0, 1] on the speed colour map (clamped; NaN gives [`NO_VALUE`]).
pub fn speed_color(t: f64) -> Rgb<u8> {
    if !t.is_finite() {
        return NO_VALUE;
    }
    let x = t.clamp(0.0, 1.0) * (PLASMA.len() - 1) as f64;
    let i = (x.floor() as usize).min(PLASMA.len() - 2);
    let f = x - i as f64;
    let (a, b) = (PLASMA[i], PLASMA[i + 1]);
    Rgb(std::array::from_fn(|k| {
        (f64::from(a[k]) + f * (f64::from(b[k]) - f64::from(a[k]))).round() as u8
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn class_colours_are_distinct() {
        let all = TerrainClass::ALL.map(class_color);
        for (i, a) in all.iter().enumerate() {
            for b in &all[i + 1..] {
                let d: i32 = (0..3)
                    .map(|k| (i32::from(a[k]) - i32::from(b[k])).abs())
                    .sum();
                assert!(d > 40, "{a:?} and {b:?} are too close");
            }
        }
    }

    #[test]
    fn speed_map_ends_and_clamps() {
        assert_eq!(speed_color(0.0), Rgb(PLASMA[0]));
        assert_eq!(speed_color(1.0), Rgb(PLASMA[8]));
        assert_eq!(speed_color(7.0), speed_color(1.0));
        assert_eq!(speed_color(f64::NAN), NO_VALUE);
    }
}
