//! Numbers of a result line that may be undefined.
//!
//! JSON has no NaN or infinity: serde_json writes them as `null`, and a plain `f64` field then
//! refuses to read its own output back. An `error` trial has no final distance (NaN), and a
//! diverged simulation can leave any statistic non-finite; a results file must still be read by
//! `report`, `--resume`, `merge` and `replay`, or one bad trial would poison the whole run. So
//! every `f64` of a result goes through this module: a non-finite number is written as `null`
//! and `null` reads back as NaN (an infinity is not kept apart from NaN: both mean "undefined").

use serde::{Deserialize, Deserializer, Serializer};

pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    if x.is_finite() {
        s.serialize_f64(*x)
    } else {
        s.serialize_none()
    }
}

pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}
