//! The perception-noise model: what it perturbs, its presets, and its YAML form.
//!
//! Every distance is at full world scale (metres of a 1:1 world) and is multiplied by the
//! world's scale, as the benchmark's other distances are; angles are in degrees.

use serde::{Deserialize, Serialize};
use verti_world::TerrainClass;

/// Number of terrain classes (Verti-Bench label ids 0..9).
pub const CLASSES: usize = 10;

/// State estimation: white noise on every observation plus a random-walk drift.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PoseNoise {
    /// Standard deviation of the white position error per observation (x, y, z), m.
    pub position_sigma: f64,
    /// Random-walk drift of the x, y position estimate, m per √s.
    pub position_drift: f64,
    /// White heading error, degrees.
    pub yaw_sigma_deg: f64,
    /// Random-walk drift of the heading estimate, degrees per √s.
    pub yaw_drift_deg: f64,
    /// White roll and pitch error, degrees.
    pub attitude_sigma_deg: f64,
}

/// Velocity estimation: white noise on every observation.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VelocityNoise {
    /// Body-frame linear velocity, m/s per axis.
    pub linear_sigma: f64,
    /// Body-frame angular velocity, degrees/s per axis.
    pub angular_sigma_deg: f64,
}

/// The elevation map a system reads.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ElevationNoise {
    /// Per-cell height error, fixed for a trial (a map is built once, its errors persist), m.
    pub sigma: f64,
    /// Fraction of map vertices with no return, filled from their neighbours as mapping
    /// stacks in-paint holes.
    pub hole_fraction: f64,
    /// Sensing range around the vehicle, m: beyond it the map is unknown and reads as level
    /// ground at the vehicle's height. 0 = unlimited.
    pub range: f64,
    /// Registration latency, s: the map seen is shifted by what the vehicle travelled in this
    /// time (speed x latency along its heading), smearing terrain features at speed.
    pub latency: f64,
}

/// Terrain-class recognition.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SemanticNoise {
    /// Probability that a patch is seen as another class, uniformly among the other nine.
    pub confusion: f64,
    /// A full confusion matrix instead: row i gives P(seen as j | true class i), rows sum to 1.
    /// Overrides `confusion`.
    pub matrix: Option<Vec<Vec<f64>>>,
}

/// Obstacle detection.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ObstacleNoise {
    /// Probability that an obstacle is not seen at all.
    pub miss_probability: f64,
    /// Phantom obstacles (false positives) per hectare of map at full scale.
    pub false_per_hectare: f64,
}

/// A perception-noise model. Applied to what systems observe, never to the physics or the
/// rules: the vehicle drives on the true world and is judged on it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PerceptionModel {
    /// A name for results and run records.
    pub name: String,
    pub pose: PoseNoise,
    pub velocity: VelocityNoise,
    pub elevation: ElevationNoise,
    pub semantics: SemanticNoise,
    pub obstacles: ObstacleNoise,
}

/// The built-in presets, mildest first.
pub const PRESETS: [&str; 4] = ["none", "low", "medium", "high"];

impl PerceptionModel {
    /// A preset by name (`none`, `low`, `medium`, `high`).
    ///
    /// `low` is a well-localised robot with a good lidar map; `medium` a typical field robot
    /// (visual-inertial odometry drifting ~1 % of a 30-m task, 0.1-m map noise, 30-m range);
    /// `high` a poor one (GPS-denied drift, a noisy short-range depth camera, 30 % class
    /// confusion). Tasks span ~30-60 m at 2 m/s, so drifts are chosen to accumulate 0.2 m,
    /// 0.5 m and 1.5 m over a 30-s trial.
    pub fn preset(name: &str) -> Option<PerceptionModel> {
        let (pos, drift, yaw, yaw_drift, att, vel, angv, h, holes, range, lat, conf, miss, fp) =
            match name {
                "none" => return Some(PerceptionModel::none()),
                "low" => (
                    0.02, 0.04, 0.5, 0.1, 0.2, 0.05, 1.0, 0.02, 0.01, 0.0, 0.05, 0.02, 0.02, 0.5,
                ),
                "medium" => (
                    0.05, 0.1, 1.0, 0.3, 0.5, 0.1, 2.0, 0.05, 0.05, 30.0, 0.1, 0.1, 0.1, 2.0,
                ),
                "high" => (
                    0.15, 0.3, 3.0, 1.0, 1.5, 0.3, 5.0, 0.15, 0.15, 15.0, 0.2, 0.3, 0.25, 6.0,
                ),
                _ => return None,
            };
        Some(PerceptionModel {
            name: name.into(),
            pose: PoseNoise {
                position_sigma: pos,
                position_drift: drift,
                yaw_sigma_deg: yaw,
                yaw_drift_deg: yaw_drift,
                attitude_sigma_deg: att,
            },
            velocity: VelocityNoise {
                linear_sigma: vel,
                angular_sigma_deg: angv,
            },
            elevation: ElevationNoise {
                sigma: h,
                hole_fraction: holes,
                range,
                latency: lat,
            },
            semantics: SemanticNoise {
                confusion: conf,
                matrix: None,
            },
            obstacles: ObstacleNoise {
                miss_probability: miss,
                false_per_hectare: fp,
            },
        })
    }

    /// No noise: systems see the ground truth (the benchmark's default).
    pub fn none() -> PerceptionModel {
        PerceptionModel {
            name: "none".into(),
            ..Default::default()
        }
    }

    /// A preset name, or a YAML file with any subset of the fields (the rest are zero).
    pub fn load(spec: &str) -> Result<PerceptionModel, String> {
        if let Some(m) = PerceptionModel::preset(spec) {
            return Ok(m);
        }
        let path = std::path::Path::new(spec);
        if !path.exists() {
            return Err(format!(
                "unknown perception `{spec}`: use one of {} or a YAML file",
                PRESETS.join(", ")
            ));
        }
        let text = verti_world::yaml::read_yaml_bounded(
            path,
            &verti_world::yaml::YamlLimits::DEFAULT,
            "a perception file",
        )
        .map_err(|e| e.to_string())?;
        let mut m: PerceptionModel = serde_norway::from_str(&text).map_err(|e| {
            format!(
                "{}: {}",
                path.display(),
                verti_core::messages::explain_serde_error(&e.to_string())
            )
        })?;
        if m.name.is_empty() {
            m.name = path
                .file_stem()
                .map_or_else(|| spec.to_string(), |s| s.to_string_lossy().into_owned());
        }
        m.validate()
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(m)
    }

    /// True when nothing is perturbed.
    pub fn is_none(&self) -> bool {
        PerceptionModel {
            name: String::new(),
            ..self.clone()
        } == PerceptionModel::default()
    }

    /// True when the state estimate is exact (no pose or velocity noise): only the map is
    /// perturbed, and systems get the true state bit for bit.
    pub fn exact_state(&self) -> bool {
        self.pose == PoseNoise::default() && self.velocity == VelocityNoise::default()
    }

    /// Checks every field; names the first bad one.
    pub fn validate(&self) -> Result<(), String> {
        let non_negative = [
            ("pose.position_sigma", self.pose.position_sigma),
            ("pose.position_drift", self.pose.position_drift),
            ("pose.yaw_sigma_deg", self.pose.yaw_sigma_deg),
            ("pose.yaw_drift_deg", self.pose.yaw_drift_deg),
            ("pose.attitude_sigma_deg", self.pose.attitude_sigma_deg),
            ("velocity.linear_sigma", self.velocity.linear_sigma),
            (
                "velocity.angular_sigma_deg",
                self.velocity.angular_sigma_deg,
            ),
            ("elevation.sigma", self.elevation.sigma),
            ("elevation.range", self.elevation.range),
            ("elevation.latency", self.elevation.latency),
            (
                "obstacles.false_per_hectare",
                self.obstacles.false_per_hectare,
            ),
        ];
        for (name, v) in non_negative {
            if !v.is_finite() || v < 0.0 {
                return Err(format!("field {name} = {v}: must be finite and >= 0"));
            }
        }
        let probabilities = [
            ("elevation.hole_fraction", self.elevation.hole_fraction),
            ("semantics.confusion", self.semantics.confusion),
            (
                "obstacles.miss_probability",
                self.obstacles.miss_probability,
            ),
        ];
        for (name, v) in probabilities {
            if !(0.0..=1.0).contains(&v) {
                return Err(format!(
                    "field {name} = {v}: must be a probability in [0, 1]"
                ));
            }
        }
        if self.elevation.hole_fraction > 0.9 {
            return Err(format!(
                "field elevation.hole_fraction = {}: at most 0.9 (a map needs returns to fill holes from)",
                self.elevation.hole_fraction
            ));
        }
        if let Some(m) = &self.semantics.matrix {
            if m.len() != CLASSES {
                return Err(format!(
                    "field semantics.matrix: {} rows, expected {CLASSES} (one per class)",
                    m.len()
                ));
            }
            for (i, row) in m.iter().enumerate() {
                if row.len() != CLASSES {
                    return Err(format!(
                        "field semantics.matrix row {i}: {} entries, expected {CLASSES}",
                        row.len()
                    ));
                }
                if row.iter().any(|p| !p.is_finite() || *p < 0.0) {
                    return Err(format!(
                        "field semantics.matrix row {i}: entries must be finite and >= 0"
                    ));
                }
                let sum: f64 = row.iter().sum();
                if (sum - 1.0).abs() > 1e-6 {
                    return Err(format!(
                        "field semantics.matrix row {i} ({}) sums to {sum}, not 1",
                        TerrainClass::from_id(i as i64).map_or("?", |c| c.name())
                    ));
                }
            }
        }
        Ok(())
    }

    /// P(seen as j | true class i), from the matrix or the uniform confusion rate.
    pub fn confusion_row(&self, true_class: usize) -> [f64; CLASSES] {
        if let Some(m) = &self.semantics.matrix {
            return std::array::from_fn(|j| m[true_class][j]);
        }
        let c = self.semantics.confusion;
        std::array::from_fn(|j| {
            if j == true_class {
                1.0 - c
            } else {
                c / (CLASSES - 1) as f64
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_validate_and_grow_in_severity() {
        let ms: Vec<PerceptionModel> = PRESETS
            .iter()
            .map(|n| PerceptionModel::preset(n).unwrap())
            .collect();
        for m in &ms {
            m.validate().unwrap();
        }
        assert!(ms[0].is_none() && !ms[1].is_none());
        for w in ms.windows(2) {
            assert!(w[1].pose.position_drift > w[0].pose.position_drift);
            assert!(w[1].elevation.sigma > w[0].elevation.sigma);
            assert!(w[1].semantics.confusion > w[0].semantics.confusion);
            assert!(w[1].obstacles.miss_probability > w[0].obstacles.miss_probability);
        }
    }

    #[test]
    fn yaml_fills_the_rest_with_zero_and_bad_fields_are_named() {
        let m: PerceptionModel =
            serde_norway::from_str("pose: {position_drift: 0.2}\nsemantics: {confusion: 0.5}")
                .unwrap();
        assert_eq!(m.pose.position_drift, 0.2);
        assert_eq!(m.elevation, ElevationNoise::default());
        let row = m.confusion_row(3);
        assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-12 && row[3] == 0.5);
        let bad = PerceptionModel {
            semantics: SemanticNoise {
                confusion: 1.5,
                matrix: None,
            },
            ..Default::default()
        };
        assert!(bad.validate().unwrap_err().contains("semantics.confusion"));
        assert!(serde_norway::from_str::<PerceptionModel>("pose: {sigma: 1}").is_err());
        let mut rows = vec![vec![0.1; CLASSES]; CLASSES];
        rows[4][0] = 0.2;
        let bad = PerceptionModel {
            semantics: SemanticNoise {
                confusion: 0.0,
                matrix: Some(rows),
            },
            ..Default::default()
        };
        assert!(bad.validate().unwrap_err().contains("row 4"));
        assert!(
            PerceptionModel::load("nonsense")
                .unwrap_err()
                .contains("unknown perception")
        );
    }
}
