//! A differential of the powertrain: locked, open, or open with a clutch (Chrono's "locked"),
//! and how it reads and writes in a vehicle file.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(into = "DifferentialRepr")]
pub enum Differential {
    /// Both outputs turn at the same speed (wheels share one spin degree of freedom).
    Locked,
    /// Equal torque to both outputs; speeds are free.
    Open,
    /// Open, with a clutch between its two output shafts that holds them together while that
    /// takes at most this torque \[N m\] and slips beyond it: what Chrono's vehicles call a
    /// locked differential (`ChShaftsClutch` with the driveline's locking limit, 100 N m for
    /// the HMMWV). For an axle differential the shafts turn with the wheels; for the central
    /// one they are the driveshafts to the two axles, `1 / final_drive` times faster. In YAML
    /// `{clutch: 100.0}`.
    Clutch(f64),
}

/// How a [`Differential`] is written in YAML: `locked`, `open` or `{clutch: TORQUE}`.
#[derive(Clone, Serialize)]
#[serde(untagged)]
enum DifferentialRepr {
    Name(&'static str),
    Clutch { clutch: f64 },
}

/// Reads `locked`, `open` or `{clutch: TORQUE}`; anything else is named in the error.
impl<'de> Deserialize<'de> for Differential {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Differential, D::Error> {
        use serde::de::{self, MapAccess, Visitor};
        const FORMS: &str = "locked, open or {clutch: TORQUE}";
        struct Forms;
        impl<'de> Visitor<'de> for Forms {
            type Value = Differential;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(FORMS)
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<Differential, E> {
                match s {
                    "locked" => Ok(Differential::Locked),
                    "open" => Ok(Differential::Open),
                    other => Err(E::custom(format!(
                        "unknown differential `{other}`: use {FORMS}"
                    ))),
                }
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Differential, A::Error> {
                let mut clutch = None;
                while let Some(key) = map.next_key::<String>()? {
                    if key != "clutch" {
                        return Err(de::Error::custom(format!(
                            "unknown field `{key}`: a differential is {FORMS}"
                        )));
                    }
                    clutch = Some(map.next_value::<f64>()?);
                }
                clutch
                    .map(Differential::Clutch)
                    .ok_or_else(|| de::Error::custom(format!("a differential is {FORMS}")))
            }
        }
        d.deserialize_any(Forms)
    }
}

impl From<Differential> for DifferentialRepr {
    fn from(d: Differential) -> DifferentialRepr {
        match d {
            Differential::Locked => DifferentialRepr::Name("locked"),
            Differential::Open => DifferentialRepr::Name("open"),
            Differential::Clutch(clutch) => DifferentialRepr::Clutch { clutch },
        }
    }
}
