//! Scripted key input: a person's inputs as text, replayed headless (tests, and re-driving a
//! recorded demonstration without a screen).
//!
//! ```text
//! # seconds   keys held from then on (up down left right brake, or none)
//! 0.0   up
//! 3.0   up left
//! 4.5   up
//! 30    brake
//! ```

use crate::driver::Keys;
use crate::session::DriveSession;
use verti_bench::Outcome;

/// Key changes at increasing times.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyScript {
    events: Vec<(f64, Keys)>,
}

impl KeyScript {
    /// Parses the text form; errors name the line.
    pub fn parse(text: &str) -> Result<KeyScript, String> {
        let mut events: Vec<(f64, Keys)> = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let at = |m: String| format!("line {}: {m}", i + 1);
            let mut words = line.split_whitespace();
            let t: f64 = words
                .next()
                .and_then(|w| w.parse().ok())
                .filter(|t: &f64| t.is_finite() && *t >= 0.0)
                .ok_or_else(|| at(format!("`{line}` must start with a time in seconds")))?;
            if let Some((last, _)) = events.last()
                && t < *last
            {
                return Err(at(format!("time {t} comes before {last}")));
            }
            let mut k = Keys::default();
            for w in words {
                match w {
                    "up" => k.up = true,
                    "down" => k.down = true,
                    "left" => k.left = true,
                    "right" => k.right = true,
                    "brake" => k.brake = true,
                    "none" => {}
                    other => {
                        return Err(at(format!(
                            "unknown key `{other}`: use up, down, left, right, brake or none"
                        )));
                    }
                }
            }
            events.push((t, k));
        }
        if events.is_empty() {
            return Err("the key script is empty".into());
        }
        Ok(KeyScript { events })
    }

    /// The keys held at time `t`.
    pub fn at(&self, t: f64) -> Keys {
        self.events
            .iter()
            .take_while(|(s, _)| *s <= t + 1e-9)
            .last()
            .map_or_else(Keys::default, |(_, k)| *k)
    }

    /// Drives `session` with the script as fast as the simulator runs, until the trial ends.
    pub fn drive(&self, session: &mut DriveSession) -> Outcome {
        loop {
            let keys = self.at(session.time());
            if let Some(o) = session.step(keys) {
                return o;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scripts_hold_keys_until_the_next_line() {
        let s = KeyScript::parse("# a comment\n0 up\n2.5 up left # turning\n4 none\n").unwrap();
        assert!(s.at(0.0).up && !s.at(1.0).left);
        assert!(s.at(2.5).up && s.at(3.0).left);
        assert_eq!(s.at(10.0), Keys::default());
        assert!(
            KeyScript::parse("1 up\n0 down")
                .unwrap_err()
                .contains("line 2")
        );
        assert!(KeyScript::parse("0 jump").unwrap_err().contains("`jump`"));
        assert!(KeyScript::parse("x up").unwrap_err().contains("line 1"));
        assert!(KeyScript::parse("# nothing").is_err());
    }
}
