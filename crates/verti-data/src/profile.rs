//! Command profiles of random exploration: what the "random driver" commands at time t.

use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use verti_core::rng::Rng;

/// Which exploration profile.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// Verti-Bench §III-G.2: sinusoidal steering and a 2 m/s speed command. The paper gives no
    /// frequency; we draw it as VertiAdaptor does, f_s ~ U(0.1, 0.5) Hz, full-lock amplitude.
    #[default]
    Paper,
    /// VertiAdaptor §IV-A: steer(t) = sin(2π f_s t + φ), f_s ~ U(0.1, 0.5) Hz; speed(t) = v_c +
    /// A sin(2π f_v t), f_v ~ U(0.1, 2.5) Hz, v_min ~ U(0, 2), v_max = 3 m/s, v_c = (v_min + 3)/2,
    /// A = (3 − v_min)/2.
    VertiAdaptor,
}

impl Profile {
    pub fn name(self) -> &'static str {
        match self {
            Profile::Paper => "paper",
            Profile::VertiAdaptor => "vertiadaptor",
        }
    }

    pub fn from_name(s: &str) -> Option<Profile> {
        [Profile::Paper, Profile::VertiAdaptor]
            .into_iter()
            .find(|p| p.name() == s)
    }

    /// Draws one trial's parameters.
    pub fn draw(self, rng: &mut Rng) -> Commands {
        // the draws are made in the same order for both profiles, so a trial's steering is the
        // same under either profile with the same seed
        let steer_hz = rng.range(0.1, 0.5);
        let steer_phase = rng.range(0.0, TAU);
        let speed_hz = rng.range(0.1, 2.5);
        let v_min = rng.range(0.0, 2.0);
        match self {
            Profile::Paper => Commands {
                steer_hz,
                steer_phase,
                speed_centre: 2.0,
                speed_amplitude: 0.0,
                speed_hz: 0.0,
            },
            Profile::VertiAdaptor => Commands {
                steer_hz,
                steer_phase,
                speed_centre: 0.5 * (v_min + V_MAX),
                speed_amplitude: 0.5 * (V_MAX - v_min),
                speed_hz,
            },
        }
    }
}

/// VertiAdaptor's top speed command, m/s.
pub const V_MAX: f64 = 3.0;

/// One trial's sinusoidal commands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Commands {
    pub steer_hz: f64,
    pub steer_phase: f64,
    pub speed_centre: f64,
    pub speed_amplitude: f64,
    pub speed_hz: f64,
}

impl Commands {
    /// (steering in [-1, 1], + left; target speed, m/s) at trial time `t`.
    pub fn at(&self, t: f64) -> (f64, f64) {
        (
            (TAU * self.steer_hz * t + self.steer_phase).sin(),
            self.speed_centre + self.speed_amplitude * (TAU * self.speed_hz * t).sin(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_stay_in_their_ranges() {
        let mut rng = Rng::new(7);
        for _ in 0..1000 {
            let p = Profile::VertiAdaptor.draw(&mut rng);
            assert!((0.1..0.5).contains(&p.steer_hz));
            assert!((0.1..2.5).contains(&p.speed_hz));
            for k in 0..100 {
                let (s, v) = p.at(k as f64 * 0.37);
                assert!(s.abs() <= 1.0);
                assert!((-1e-12..=V_MAX + 1e-12).contains(&v), "{v}");
            }
            let q = Profile::Paper.draw(&mut rng);
            assert_eq!(q.at(3.3).1, 2.0);
        }
        assert_eq!(
            Profile::from_name("vertiadaptor"),
            Some(Profile::VertiAdaptor)
        );
        assert_eq!(Profile::from_name("x"), None);
    }
}
