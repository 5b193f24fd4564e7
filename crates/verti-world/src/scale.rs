//! World scale: every length in a world (cells, heights, obstacles, task circle, clearances)
//! is multiplied by it so 1/6- and 1/10-scale vehicles get proportional worlds.

use crate::error::{Result, WorldError};

/// Parses a scale written as a decimal (`0.1`, `1`) or a fraction (`1/6`, `1/10`).
/// Accepted range: [1/1000, 10].
pub fn parse_scale(text: &str) -> Result<f64> {
    let t = text.trim();
    let value = if let Some((num, den)) = t.split_once('/') {
        let n: f64 = num.trim().parse().map_err(|_| {
            WorldError::Argument(format!("scale `{text}`: numerator `{num}` is not a number"))
        })?;
        let d: f64 = den.trim().parse().map_err(|_| {
            WorldError::Argument(format!(
                "scale `{text}`: denominator `{den}` is not a number"
            ))
        })?;
        if d == 0.0 {
            return Err(WorldError::Argument(format!(
                "scale `{text}`: denominator is zero"
            )));
        }
        n / d
    } else {
        t.parse().map_err(|_| {
            WorldError::Argument(format!(
                "scale `{text}` is not a number or a fraction like 1/6"
            ))
        })?
    };
    check_scale(value)?;
    Ok(value)
}

/// Smallest accepted scale: a 13 cm world, already 100 times smaller than the smallest vehicle
/// verti ships (1/10). Far below it lengths reach the fixed tolerances of contact, soil and
/// planning, and near 1e-300 they underflow f64 (a rock's faces square to zero).
pub const MIN_SCALE: f64 = 1e-3;
/// Largest accepted scale.
pub const MAX_SCALE: f64 = 10.0;

/// Rejects scales that are not finite or outside [1/1000, 10].
pub fn check_scale(value: f64) -> Result<()> {
    if !(value.is_finite() && (MIN_SCALE..=MAX_SCALE).contains(&value)) {
        return Err(WorldError::Argument(format!(
            "scale {value} is out of range: it must be in [1/1000, 10], e.g. 1, 1/6 or 1/10"
        )));
    }
    Ok(())
}

/// A short label for file and set names: `1`, `1/6`, `1/10`, or the decimal.
pub fn scale_label(value: f64) -> String {
    for den in 1..=20u32 {
        if (value * f64::from(den) - 1.0).abs() < 1e-9 {
            return if den == 1 {
                "1".into()
            } else {
                format!("1/{den}")
            };
        }
    }
    format!("{value}")
}

/// The one scale of a loaded set, checked against a scale the user asked for. Generated and
/// imported sets are built at the requested scale; saved sets (and worlds) carry their own, so
/// asking for another one is an error rather than being ignored, and a set whose worlds differ
/// in scale is refused (lengths, speeds and rules all depend on it).
pub fn set_scale<'a>(
    spec: &str,
    worlds: impl IntoIterator<Item = &'a crate::World>,
    requested: Option<f64>,
) -> Result<f64> {
    let mut found: Option<(f64, &str)> = None;
    for w in worlds {
        match found {
            None => found = Some((w.meta.scale, &w.meta.name)),
            Some((s, first)) if !same_scale(s, w.meta.scale) => {
                return Err(WorldError::Argument(format!(
                    "`{spec}` mixes world scales: {first} is at scale {} and {} at scale {}",
                    scale_label(s),
                    w.meta.name,
                    scale_label(w.meta.scale)
                )));
            }
            Some(_) => {}
        }
    }
    let Some((scale, _)) = found else {
        return Err(WorldError::Argument(format!("`{spec}` holds no worlds")));
    };
    if let Some(r) = requested
        && !same_scale(r, scale)
    {
        return Err(WorldError::Argument(format!(
            "--scale {} does not apply to `{spec}`: its worlds were saved at scale {} and keep it (drop --scale, or generate or import the set again at the scale you want)",
            scale_label(r),
            scale_label(scale)
        )));
    }
    Ok(scale)
}

fn same_scale(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_fractions_and_decimals() {
        assert_eq!(parse_scale("1").unwrap(), 1.0);
        assert!((parse_scale("1/6").unwrap() - 1.0 / 6.0).abs() < 1e-15);
        assert_eq!(parse_scale(" 1/10 ").unwrap(), 0.1);
        assert_eq!(parse_scale("0.25").unwrap(), 0.25);
        assert_eq!(parse_scale("1/1000").unwrap(), MIN_SCALE);
        assert_eq!(parse_scale("10").unwrap(), MAX_SCALE);
        assert_eq!(scale_label(1.0 / 6.0), "1/6");
        assert_eq!(scale_label(0.1), "1/10");
    }

    #[test]
    fn rejects_bad_scales() {
        for bad in [
            "0",
            "-1",
            "1/0",
            "abc",
            "nan",
            "inf",
            "20",
            "1/x",
            "1e-8",
            "1/10000",
            "1e-300",
            "10.000001",
        ] {
            let e = parse_scale(bad).unwrap_err().to_string();
            assert!(e.contains("scale"), "{bad}: {e}");
        }
    }
}
