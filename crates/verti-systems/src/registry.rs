//! Systems by name, with typed, documented parameters (`verti systems list`).

use crate::eh::{EhParams, ElevationHeuristic};
use crate::mppi::{Mppi, MppiParams};
use crate::pid::{Pid, PidParams};
use verti_bench::MobilitySystem;

/// One tunable parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamInfo {
    pub name: &'static str,
    pub default: f64,
    /// Accepted range (inclusive).
    pub min: f64,
    pub max: f64,
    pub doc: &'static str,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SystemInfo {
    pub name: &'static str,
    pub summary: &'static str,
    pub params: Vec<ParamInfo>,
}

fn p(name: &'static str, default: f64, min: f64, max: f64, doc: &'static str) -> ParamInfo {
    ParamInfo {
        name,
        default,
        min,
        max,
        doc,
    }
}

fn pid_params() -> Vec<ParamInfo> {
    let d = PidParams::default();
    vec![
        p(
            "speed",
            d.speed,
            0.1,
            30.0,
            "target speed at full scale, m/s (scaled by sqrt(world scale))",
        ),
        p(
            "lookahead",
            d.lookahead,
            0.5,
            60.0,
            "local goal distance along the global path at full scale, m",
        ),
        p(
            "kp",
            d.kp,
            0.0,
            20.0,
            "road-wheel angle per radian of heading error",
        ),
        p("ki", d.ki, 0.0, 20.0, "integral gain (per rad·s)"),
        p("kd", d.kd, 0.0, 20.0, "derivative gain (per rad/s)"),
        p("rate", d.rate, 1.0, 200.0, "control rate, Hz"),
    ]
}

/// Every system with its parameters and defaults.
pub fn list() -> Vec<SystemInfo> {
    let m = MppiParams::default();
    let mut eh = pid_params();
    eh.push(p(
        "terrain_weight",
        EhParams::default().terrain_weight,
        0.0,
        1.0,
        "weight of the terrain direction (path gets 1 - weight)",
    ));
    vec![
        SystemInfo {
            name: "pid",
            summary: "path follower: local goal 10 m ahead, steering from heading error, 3 m/s",
            params: pid_params(),
        },
        SystemInfo {
            name: "eh",
            summary: "elevation heuristic: PID blended toward the region ahead most like the current ground, least rough",
            params: eh,
        },
        SystemInfo {
            name: "mppi",
            summary: "MPPI with a kinematic bicycle model and obstacle avoidance, cost over the whole horizon",
            params: vec![
                p(
                    "samples",
                    m.samples as f64,
                    1.0,
                    65536.0,
                    "rollouts per plan",
                ),
                p("horizon", m.horizon as f64, 1.0, 1000.0, "rollout steps"),
                p("step", m.step, 0.01, 1.0, "rollout step, s"),
                p("lambda", m.lambda, 1e-4, 100.0, "temperature"),
                p(
                    "sigma_speed",
                    m.sigma_speed,
                    0.0,
                    10.0,
                    "speed noise at full scale, m/s",
                ),
                p(
                    "sigma_steer",
                    m.sigma_steer,
                    0.0,
                    2.0,
                    "steering noise (normalised steering)",
                ),
                p(
                    "speed",
                    m.speed,
                    0.1,
                    30.0,
                    "nominal speed at full scale, m/s",
                ),
                p(
                    "lookahead",
                    m.lookahead,
                    0.5,
                    60.0,
                    "local goal distance at full scale, m",
                ),
                p(
                    "w_goal",
                    m.w_goal,
                    0.0,
                    1e6,
                    "weight of the distance to the local goal",
                ),
                p(
                    "w_obstacle",
                    m.w_obstacle,
                    0.0,
                    1e6,
                    "cost per rollout step inside an obstacle or off the map",
                ),
                p(
                    "w_control",
                    m.w_control,
                    0.0,
                    1e6,
                    "weight of the control cost",
                ),
                p("rate", m.rate, 1.0, 200.0, "planning rate, Hz"),
            ],
        },
    ]
}

/// Checks names and ranges; returns the full parameter vector with defaults filled in.
pub fn resolve_params(
    system: &str,
    given: &[(String, f64)],
) -> Result<Vec<(&'static str, f64)>, String> {
    let info = list()
        .into_iter()
        .find(|s| s.name == system)
        .ok_or_else(|| {
            format!(
                "unknown system `{system}`; known systems: {}",
                list().iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
            )
        })?;
    let mut values: Vec<(&'static str, f64)> =
        info.params.iter().map(|p| (p.name, p.default)).collect();
    for (name, v) in given {
        let Some(pi) = info.params.iter().find(|p| p.name == name) else {
            return Err(format!(
                "system {system} has no parameter `{name}`; its parameters: {}",
                info.params
                    .iter()
                    .map(|p| p.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        };
        if !(v.is_finite() && *v >= pi.min && *v <= pi.max) {
            return Err(format!(
                "{system} parameter {name} = {v} is outside [{}, {}]",
                pi.min, pi.max
            ));
        }
        values
            .iter_mut()
            .find(|(n, _)| n == name)
            .expect("listed")
            .1 = *v;
    }
    Ok(values)
}

/// Builds a system by name. `params` override defaults.
pub fn create(system: &str, params: &[(String, f64)]) -> Result<Box<dyn MobilitySystem>, String> {
    let v = resolve_params(system, params)?;
    let get = |n: &str| {
        v.iter()
            .find(|(k, _)| *k == n)
            .map(|x| x.1)
            .expect("resolved")
    };
    let pid = || PidParams {
        speed: get("speed"),
        lookahead: get("lookahead"),
        kp: get("kp"),
        ki: get("ki"),
        kd: get("kd"),
        rate: get("rate"),
    };
    Ok(match system {
        "pid" => Box::new(Pid::new(pid())),
        "eh" => Box::new(ElevationHeuristic::new(EhParams {
            pid: pid(),
            terrain_weight: get("terrain_weight"),
        })),
        "mppi" => Box::new(Mppi::new(MppiParams {
            samples: get("samples") as usize,
            horizon: get("horizon") as usize,
            step: get("step"),
            lambda: get("lambda"),
            sigma_speed: get("sigma_speed"),
            sigma_steer: get("sigma_steer"),
            speed: get("speed"),
            lookahead: get("lookahead"),
            w_goal: get("w_goal"),
            w_obstacle: get("w_obstacle"),
            w_control: get("w_control"),
            rate: get("rate"),
        })),
        _ => unreachable!("resolve_params checked the name"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builds_every_listed_system_and_rejects_bad_input() {
        for s in list() {
            assert_eq!(create(s.name, &[]).unwrap().name(), s.name);
        }
        let e = create("nope", &[]).err().unwrap();
        assert!(
            e.contains("unknown system `nope`") && e.contains("pid"),
            "{e}"
        );
        let e = create("pid", &[("speeed".into(), 1.0)]).err().unwrap();
        assert!(e.contains("speeed") && e.contains("lookahead"), "{e}");
        let e = create("mppi", &[("samples".into(), f64::NAN)])
            .err()
            .unwrap();
        assert!(e.contains("samples"), "{e}");
    }
}
