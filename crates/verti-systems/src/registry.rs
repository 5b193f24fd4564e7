//! The factories of PID, EH and MPPI, with typed, documented parameters
//! (`verti systems list`). [`register`] adds them to a [`SystemRegistry`]; crates above this
//! one register theirs next to them (see `verti_bench::SystemRegistry`).

use crate::eh::{EhParams, ElevationHeuristic};
use crate::mppi::{Mppi, MppiParams};
use crate::oracle::{Oracle, OracleParams};
use crate::pid::{Pid, PidParams};
use verti_bench::{MobilitySystem, ParamSpec, ParamValue, Params, SystemInfo, SystemRegistry};
use verti_core::Factory;

fn pid_params() -> Vec<ParamSpec> {
    let d = PidParams::default();
    vec![
        ParamSpec::float(
            "speed",
            d.speed,
            0.1,
            30.0,
            "target speed at full scale, m/s (scaled by sqrt(world scale))",
        ),
        ParamSpec::float(
            "lookahead",
            d.lookahead,
            0.5,
            60.0,
            "local goal distance along the global path at full scale, m",
        ),
        ParamSpec::float(
            "kp",
            d.kp,
            0.0,
            20.0,
            "road-wheel angle per radian of heading error",
        ),
        ParamSpec::float("ki", d.ki, 0.0, 20.0, "integral gain (per rad·s)"),
        ParamSpec::float("kd", d.kd, 0.0, 20.0, "derivative gain (per rad/s)"),
        ParamSpec::float("rate", d.rate, 1.0, 200.0, "control rate, Hz"),
    ]
}

fn pid_from(p: &Params) -> PidParams {
    PidParams {
        speed: p.float("speed"),
        lookahead: p.float("lookahead"),
        kp: p.float("kp"),
        ki: p.float("ki"),
        kd: p.float("kd"),
        rate: p.float("rate"),
    }
}

/// PID path follower.
pub struct PidFactory;

impl Factory<dyn MobilitySystem> for PidFactory {
    fn info(&self) -> SystemInfo {
        SystemInfo {
            name: "pid".into(),
            summary: "path follower: local goal 10 m ahead, steering from heading error, 3 m/s"
                .into(),
            params: pid_params(),
        }
    }
    fn build(&self, p: &Params) -> Result<Box<dyn MobilitySystem>, String> {
        Ok(Box::new(Pid::new(pid_from(p))))
    }
}

/// Elevation heuristic.
pub struct EhFactory;

impl Factory<dyn MobilitySystem> for EhFactory {
    fn info(&self) -> SystemInfo {
        let mut params = pid_params();
        params.push(ParamSpec::float(
            "terrain_weight",
            EhParams::default().terrain_weight,
            0.0,
            1.0,
            "weight of the terrain direction (path gets 1 - weight)",
        ));
        SystemInfo {
            name: "eh".into(),
            summary: "elevation heuristic: PID blended toward the region ahead most like the current ground, least rough".into(),
            params,
        }
    }
    fn build(&self, p: &Params) -> Result<Box<dyn MobilitySystem>, String> {
        Ok(Box::new(ElevationHeuristic::new(EhParams {
            pid: pid_from(p),
            terrain_weight: p.float("terrain_weight"),
        })))
    }
}

/// The MPPI sampling parameters (`samples` .. `lambda`, `sigma_*`, `speed`, `lookahead`,
/// `rate`), for systems built on [`Mppi`] with another model and cost; [`mppi_from`] reads
/// them back.
pub fn mppi_params() -> Vec<ParamSpec> {
    let m = MppiParams::default();
    vec![
        ParamSpec::int("samples", m.samples as i64, 1, 65536, "rollouts per plan"),
        ParamSpec::int("horizon", m.horizon as i64, 1, 1000, "rollout steps"),
        ParamSpec::float(
            "step",
            m.step,
            0.01,
            1.0,
            "rollout step at full scale, s (scaled by sqrt(world scale))",
        ),
        ParamSpec::float("lambda", m.lambda, 1e-4, 100.0, "temperature"),
        ParamSpec::float(
            "sigma_speed",
            m.sigma_speed,
            0.0,
            10.0,
            "speed noise at full scale, m/s",
        ),
        ParamSpec::float(
            "sigma_steer",
            m.sigma_steer,
            0.0,
            2.0,
            "steering noise (normalised steering)",
        ),
        ParamSpec::float(
            "speed",
            m.speed,
            0.1,
            30.0,
            "nominal speed at full scale, m/s",
        ),
        ParamSpec::float(
            "lookahead",
            m.lookahead,
            0.5,
            60.0,
            "local goal distance at full scale, m",
        ),
        ParamSpec::float("rate", m.rate, 1.0, 200.0, "planning rate, Hz"),
    ]
}

/// The [`MppiParams`] among the parameters `p` of system `owner`, which may declare more than
/// [`mppi_params`] (its own model and cost settings). `step`, when given, replaces the rollout
/// step: systems whose rollouts advance one model step at a time do not offer it.
pub fn mppi_among(owner: &str, p: &Params, step: Option<f64>) -> Result<MppiParams, String> {
    let specs = mppi_params();
    let mut pairs: Vec<(String, ParamValue)> = p
        .to_pairs()
        .into_iter()
        .filter(|(n, _)| specs.iter().any(|s| &s.name == n))
        .collect();
    if let Some(step) = step {
        pairs.retain(|(n, _)| n != "step");
        pairs.push(("step".into(), ParamValue::Float(step)));
    }
    let m = mppi_from(&Params::resolve(owner, specs, &pairs).map_err(|e| e.to_string())?);
    check_plan_memory(&m, verti_core::memory::usable_bytes())?;
    Ok(m)
}

/// Memory one MPPI plan holds per sampled rollout step (noise, controls, poses, cost terms and
/// the model's own buffers), bytes: measured as the growth of the peak resident size with
/// `samples × horizon` (about 80 B for mppi and tal, 140 B for pietra), rounded up.
pub const PLAN_BYTES_PER_STEP: u64 = 160;

/// Refuses MPPI settings whose plan cannot fit: `samples × horizon` rollout steps at
/// [`PLAN_BYTES_PER_STEP`] each must stay within a quarter of the memory this process may use
/// (`usable`; unchecked when unknown), leaving room for a few jobs and the worlds. Without
/// this, an allowed but huge combination aborted the process on allocation failure.
pub fn check_plan_memory(m: &MppiParams, usable: Option<u64>) -> Result<(), String> {
    let Some(usable) = usable else {
        return Ok(());
    };
    let steps = (m.samples as u64).saturating_mul(m.horizon as u64);
    let need = steps.saturating_mul(PLAN_BYTES_PER_STEP);
    if need > usable / 4 {
        let human = verti_core::memory::human;
        return Err(format!(
            "samples {} x horizon {} = {steps} rollout steps per plan need about {} per job, more than a quarter of the {} this process may use (the smaller of `ulimit -v` and the machine's memory): lower samples or horizon",
            m.samples,
            m.horizon,
            human(need),
            human(usable)
        ));
    }
    Ok(())
}

/// [`MppiParams`] from parameters declared by [`mppi_params`] (cost weights, when not
/// declared, at their defaults).
pub fn mppi_from(p: &Params) -> MppiParams {
    let d = MppiParams::default();
    let weight = |name: &str, default: f64| match p.get(name) {
        Some(ParamValue::Float(w)) => *w,
        _ => default,
    };
    MppiParams {
        samples: p.usize("samples"),
        horizon: p.usize("horizon"),
        step: p.float("step"),
        lambda: p.float("lambda"),
        sigma_speed: p.float("sigma_speed"),
        sigma_steer: p.float("sigma_steer"),
        speed: p.float("speed"),
        lookahead: p.float("lookahead"),
        w_goal: weight("w_goal", d.w_goal),
        w_obstacle: weight("w_obstacle", d.w_obstacle),
        w_control: weight("w_control", d.w_control),
        rate: p.float("rate"),
    }
}

/// MPPI with the kinematic bicycle model and the path cost.
pub struct MppiFactory;

impl Factory<dyn MobilitySystem> for MppiFactory {
    fn info(&self) -> SystemInfo {
        let m = MppiParams::default();
        let mut params = mppi_params();
        let rate = params.pop().expect("rate is last");
        params.extend([
            ParamSpec::float(
                "w_goal",
                m.w_goal,
                0.0,
                1e6,
                "weight of the distance to the local goal",
            ),
            ParamSpec::float(
                "w_obstacle",
                m.w_obstacle,
                0.0,
                1e6,
                "cost per rollout step inside an obstacle or off the map",
            ),
            ParamSpec::float(
                "w_control",
                m.w_control,
                0.0,
                1e6,
                "weight of the control cost",
            ),
            rate,
        ]);
        SystemInfo {
            name: "mppi".into(),
            summary: "MPPI with a kinematic bicycle model and obstacle avoidance, cost over the whole horizon".into(),
            params,
        }
    }
    fn build(&self, p: &Params) -> Result<Box<dyn MobilitySystem>, String> {
        let m = mppi_from(p);
        check_plan_memory(&m, verti_core::memory::usable_bytes())?;
        Ok(Box::new(Mppi::new(m)))
    }
}

/// The oracle: sampling MPC with the true simulator (privileged).
pub struct OracleFactory;

impl Factory<dyn MobilitySystem> for OracleFactory {
    fn info(&self) -> SystemInfo {
        let d = OracleParams::default();
        SystemInfo {
            name: "oracle".into(),
            summary: "PRIVILEGED upper bound: sampling MPC whose rollouts are branches of the running trial (the true simulator)".into(),
            params: vec![
                ParamSpec::int("samples", d.samples as i64, 1, 4096, "candidate plans per replanning instant"),
                ParamSpec::float("horizon", d.horizon, 0.1, 30.0, "planning horizon, s (a multiple of 0.1 s)"),
                ParamSpec::int("segments", d.segments as i64, 1, 300, "piecewise-constant segments per plan (horizon / segments: whole 0.1 s ticks)"),
                ParamSpec::float("replan", d.replan, 0.1, 30.0, "replanning period, s (a multiple of 0.1 s, at most a segment)"),
                ParamSpec::float("speed", d.speed, 0.1, 30.0, "nominal target speed at full scale, m/s"),
                ParamSpec::float("min_speed", d.min_speed, 0.1, 30.0, "lowest sampled target speed at full scale, m/s"),
                ParamSpec::float("max_speed", d.max_speed, 0.1, 30.0, "highest sampled target speed at full scale, m/s"),
                ParamSpec::float("lane", d.lane, 0.0, 100.0, "lateral offset between route-tracking candidates at full scale, m"),
                ParamSpec::float("lookahead", d.lookahead, 0.5, 60.0, "route-tracking lookahead at full scale, m"),
                ParamSpec::float("w_tilt", d.w_tilt, 0.0, 1e3, "weight of the roll/pitch penalty beyond 15 deg / 20 deg"),
            ],
        }
    }
    fn build(&self, p: &Params) -> Result<Box<dyn MobilitySystem>, String> {
        Ok(Box::new(Oracle::new(OracleParams {
            samples: p.usize("samples"),
            horizon: p.float("horizon"),
            segments: p.usize("segments"),
            replan: p.float("replan"),
            speed: p.float("speed"),
            min_speed: p.float("min_speed"),
            max_speed: p.float("max_speed"),
            lane: p.float("lane"),
            lookahead: p.float("lookahead"),
            w_tilt: p.float("w_tilt"),
        })?))
    }
}

/// Adds PID, EH, MPPI and the oracle to a registry.
pub fn register(registry: &mut SystemRegistry) {
    for r in [
        registry.register(PidFactory),
        registry.register(EhFactory),
        registry.register(MppiFactory),
        registry.register(OracleFactory),
    ] {
        r.expect("the built-in systems are declared correctly and registered once");
    }
}

/// A registry of the built-in systems only (PID, EH, MPPI, oracle).
pub fn builtin() -> SystemRegistry {
    let mut r = SystemRegistry::new();
    register(&mut r);
    r
}

/// Every built-in system with its parameters and defaults.
pub fn list() -> Vec<SystemInfo> {
    builtin().list().cloned().collect()
}

/// Builds a built-in system by name; `params` override defaults.
pub fn create(
    system: &str,
    params: &[(String, ParamValue)],
) -> Result<Box<dyn MobilitySystem>, String> {
    builtin().create(system, params).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plan_that_cannot_fit_is_refused_with_its_size() {
        let m = MppiParams {
            samples: 65536,
            horizon: 1000,
            ..MppiParams::default()
        };
        // `ulimit -v 4000000` (KiB): the repro that aborted on allocation failure
        let e = check_plan_memory(&m, Some(4_000_000 * 1024)).unwrap_err();
        assert!(
            e.contains("65536000 rollout steps") && e.contains("10.5 GB"),
            "{e}"
        );
        // the defaults fit a small machine; nothing is checked where memory is unknown
        assert!(check_plan_memory(&MppiParams::default(), Some(1 << 30)).is_ok());
        assert!(check_plan_memory(&m, None).is_ok());
    }

    #[test]
    fn builds_every_listed_system_and_rejects_bad_input() {
        for s in list() {
            assert_eq!(create(&s.name, &[]).unwrap().name(), s.name);
        }
        let e = create("nope", &[]).err().unwrap();
        assert!(
            e.contains("unknown system `nope`") && e.contains("pid"),
            "{e}"
        );
        let e = create("pid", &[("speeed".into(), 1.0.into())])
            .err()
            .unwrap();
        assert!(e.contains("speeed") && e.contains("lookahead"), "{e}");
        let e = create("mppi", &[("samples".into(), f64::NAN.into())])
            .err()
            .unwrap();
        assert!(e.contains("samples"), "{e}");
        let r = builtin();
        let e = r
            .parse_param("mppi", "samples=12.5")
            .unwrap_err()
            .to_string();
        assert!(e.contains("system mppi parameter samples"), "{e}");
        let e = r.parse_param("mppi", "lambda=0").unwrap_err().to_string();
        assert!(e.contains("lambda: 0 is outside [0.0001, 100]"), "{e}");
    }

    #[test]
    fn typed_parameters_reach_the_system() {
        let r = builtin();
        let p = r
            .resolve("mppi", &[r.parse_param("mppi", "samples=64").unwrap()])
            .unwrap();
        let m = mppi_from(&p);
        assert_eq!((m.samples, m.horizon), (64, 30));
        assert_eq!(
            MppiParams {
                samples: 800,
                ..m.clone()
            },
            MppiParams::default()
        );
    }
}
