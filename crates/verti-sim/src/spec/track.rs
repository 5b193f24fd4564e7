//! The track of a tracked vehicle: its mass, and where its raised ends run.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackSpec {
    /// Mass of one track (all shoes) \[kg\]; counted as sprung mass and as spin inertia of its side.
    pub track_mass: f64,
    /// The track's raised ends: the drive sprocket ahead of the first road wheel and the idler
    /// behind the last one, each wrapped by the track. Given, the runs from the first road
    /// wheel up to the sprocket and from the last one up to the idler touch the ground and
    /// obstacles, and the moving track drives the vehicle over what they touch
    /// (`contact::track_run`). Absent, only the road wheels touch anything.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runs: Option<TrackRunsSpec>,
}

/// Where the track leaves the ground at both ends (chassis reference frame, x forward, z up;
/// both sides alike, at the road wheels' lateral position).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackRunsSpec {
    /// The front roller (the drive sprocket): its centre and the radius of the track's outer
    /// surface around it.
    pub sprocket: RollerSpec,
    /// The rear roller (the idler), likewise.
    pub idler: RollerSpec,
}

/// A roller the track wraps: its axis' position and the radius of the track's ground-facing
/// surface around it \[m\].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollerSpec {
    pub x: f64,
    pub z: f64,
    pub radius: f64,
}

impl TrackRunsSpec {
    /// Checks the rollers against the road wheels (x and z of the axles' wheel centres,
    /// front first, and the road wheels' radius): each roller must be finite, have a positive
    /// radius, lie beyond the road wheel at its end and leave room for a straight run between
    /// the two (their circles must not contain one another). Returns the bad field and why.
    pub(crate) fn check(
        &self,
        front: (f64, f64),
        rear: (f64, f64),
        wheel_radius: f64,
    ) -> Result<(), (String, String)> {
        let rollers = [
            ("track.runs.sprocket", &self.sprocket, front, 1.0),
            ("track.runs.idler", &self.idler, rear, -1.0),
        ];
        for (name, r, (wx, wz), ahead) in rollers {
            for (field, v) in [("x", r.x), ("z", r.z), ("radius", r.radius)] {
                if !v.is_finite() {
                    return Err((format!("{name}.{field}"), format!("{v} must be finite")));
                }
            }
            if r.radius <= 0.0 {
                return Err((
                    format!("{name}.radius"),
                    format!("{} must be a positive number", r.radius),
                ));
            }
            if (r.x - wx) * ahead <= 0.0 {
                let side = if ahead > 0.0 {
                    "ahead of the first"
                } else {
                    "behind the last"
                };
                return Err((
                    format!("{name}.x"),
                    format!("{} must lie {side} road wheel (x {wx})", r.x),
                ));
            }
            let d = ((r.x - wx).powi(2) + (r.z - wz).powi(2)).sqrt();
            if d <= (r.radius - wheel_radius).abs() {
                return Err((
                    format!("{name}.radius"),
                    format!(
                        "{}: the roller and the road wheel at x {wx} contain one another, \
                         so no straight run joins them",
                        r.radius
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl super::VehicleSpec {
    /// The belt's plate under road wheel pair `axle` (`WheelModel::belt_plate`): how far the
    /// flat lower run it carries reaches ahead of and behind its hub \[m\], half the spacing to
    /// the next road wheel each way (none beyond the end wheels, whose own tread carries
    /// outwards). `(0, 0)` for a vehicle without track runs, whose road wheels bear as wheels.
    pub fn belt_plate(&self, axle: usize) -> (f64, f64) {
        if self.track.and_then(|t| t.runs).is_none() {
            return (0.0, 0.0);
        }
        let x = self.axles[axle].x;
        let half_gap = |beyond: fn(f64, f64) -> bool| {
            let gap = self
                .axles
                .iter()
                .map(|a| a.x)
                .filter(|&o| beyond(o, x))
                .map(|o| (o - x).abs())
                .fold(f64::INFINITY, f64::min);
            if gap.is_finite() { 0.5 * gap } else { 0.0 }
        };
        (half_gap(|o, x| o > x), half_gap(|o, x| o < x))
    }
}
