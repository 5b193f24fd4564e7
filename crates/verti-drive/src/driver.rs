//! From held keys to a high-level action, the way a person drives: the accelerator raises the
//! target speed gradually, the brake lowers it faster, steering turns at a finite rate and
//! returns to centre when released.

/// The keys held during one control period. A gamepad's axes map onto the same commands
/// (`throttle` and `steer` in [-1, 1] override the arrows when non-zero).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Keys {
    pub up: bool,
    pub down: bool,
    pub left: bool,
    pub right: bool,
    /// Stop: the target speed drops to zero at once.
    pub brake: bool,
    /// Analogue throttle (+) / brake (−), e.g. a gamepad trigger or stick.
    pub throttle: f64,
    /// Analogue steering (+ = left).
    pub steer: f64,
}

impl Keys {
    /// Parses the compact form the live page sends: any of the letters `u d l r b` (up,
    /// down, left, right, brake), then optionally `,throttle,steer` for a gamepad.
    pub fn parse(s: &str) -> Result<Keys, String> {
        let mut parts = s.split(',');
        let mut k = Keys::default();
        for c in parts.next().unwrap_or("").chars() {
            match c {
                'u' => k.up = true,
                'd' => k.down = true,
                'l' => k.left = true,
                'r' => k.right = true,
                'b' => k.brake = true,
                other => return Err(format!("unknown key `{other}` in `{s}`: use u, d, l, r, b")),
            }
        }
        let axis = |p: Option<&str>, name: &str| -> Result<f64, String> {
            match p {
                None | Some("") => Ok(0.0),
                Some(v) => v
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .map(|x| x.clamp(-1.0, 1.0))
                    .ok_or_else(|| format!("{name} `{v}` is not a number")),
            }
        };
        k.throttle = axis(parts.next(), "throttle")?;
        k.steer = axis(parts.next(), "steer")?;
        Ok(k)
    }
}

/// The person's commands, updated every control period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Driver {
    /// Target forward speed (m/s) and steering in [-1, 1] (+ = left).
    pub speed: f64,
    pub steering: f64,
    /// Highest target speed (m/s; scaled with the world as √scale, like every speed).
    pub max_speed: f64,
}

/// Target-speed ramps (m/s per s at full scale) and the steering rate (full lock per s).
const ACCEL: f64 = 1.5;
const DECEL: f64 = 4.0;
const STEER_RATE: f64 = 1.5;
const CENTRE_RATE: f64 = 2.5;

impl Driver {
    /// A driver at rest for a world of `scale` (full scale 1).
    pub fn new(scale: f64) -> Driver {
        Driver {
            speed: 0.0,
            steering: 0.0,
            max_speed: 5.0 * scale.sqrt(),
        }
    }

    /// Updates the commands for `keys` held over `dt` seconds; returns (speed, steering).
    pub fn update(&mut self, keys: Keys, dt: f64) -> (f64, f64) {
        let unit = self.max_speed / 5.0;
        let pedal = if keys.throttle != 0.0 {
            keys.throttle
        } else {
            f64::from(u8::from(keys.up)) - f64::from(u8::from(keys.down))
        };
        self.speed += if pedal >= 0.0 {
            pedal * ACCEL * unit * dt
        } else {
            pedal * DECEL * unit * dt
        };
        if keys.brake {
            self.speed = 0.0;
        }
        self.speed = self.speed.clamp(0.0, self.max_speed);
        let wheel = if keys.steer != 0.0 {
            keys.steer
        } else {
            f64::from(u8::from(keys.left)) - f64::from(u8::from(keys.right))
        };
        if wheel != 0.0 {
            self.steering += wheel * STEER_RATE * dt;
        } else {
            // let go: the wheel returns to centre without overshooting
            let back = CENTRE_RATE * dt;
            self.steering -= self.steering.signum() * back.min(self.steering.abs());
        }
        self.steering = self.steering.clamp(-1.0, 1.0);
        (self.speed, self.steering)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_ramp_commands_and_steering_recentres() {
        let mut d = Driver::new(1.0);
        let up = Keys {
            up: true,
            ..Keys::default()
        };
        for _ in 0..20 {
            d.update(up, 0.1);
        }
        // 2 s at 1.5 m/s² from rest
        assert!((d.speed - 3.0).abs() < 1e-9, "{}", d.speed);
        for _ in 0..100 {
            d.update(up, 0.1);
        }
        assert_eq!(d.speed, 5.0);
        let left = Keys {
            left: true,
            ..Keys::default()
        };
        d.update(left, 0.2);
        assert!((d.steering - 0.3).abs() < 1e-9);
        d.update(Keys::default(), 0.1);
        assert!((d.steering - 0.05).abs() < 1e-9, "{}", d.steering);
        d.update(Keys::default(), 0.1);
        assert_eq!(d.steering, 0.0);
        let stop = Keys {
            brake: true,
            ..Keys::default()
        };
        d.update(stop, 0.1);
        assert_eq!(d.speed, 0.0);
        // small worlds drive slower: 1/10 scale tops out at 5·√0.1
        assert!((Driver::new(0.1).max_speed - 5.0 * 0.1f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn the_page_key_format_parses_and_bad_keys_are_named() {
        let k = Keys::parse("ul").unwrap();
        assert!(k.up && k.left && !k.right);
        let g = Keys::parse(",0.5,-2").unwrap();
        assert_eq!((g.throttle, g.steer), (0.5, -1.0));
        assert!(Keys::parse("ux").unwrap_err().contains("`x`"));
        assert!(Keys::parse("u,abc").unwrap_err().contains("throttle"));
    }
}
