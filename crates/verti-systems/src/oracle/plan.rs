//! Candidate plans, their rollouts on branches of the true trial, and their scores.
//!
//! A plan is a few segments of equal length, each a target speed and a steering *mode*: a
//! fixed normalised steering, or tracking the route at a lateral offset (see
//! [`super::route`]). The rollout of a plan and its execution call the same [`Plan::action`]
//! at the same control ticks on the same states, so a rollout predicts its execution exactly.

use super::route::Route;
use verti_bench::{Action, Outcome, Trial};
use verti_core::Rng;

/// How a segment steers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Steer {
    /// Normalised steering in [-1, 1] (positive = left).
    Fixed(f64),
    /// Track the route, offset this many metres (full scale) to its left (negative: right).
    Track(f64),
}

/// One segment: target speed at full scale (m/s) and steering.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub speed: f64,
    pub steer: Steer,
}

/// What the plan's actions depend on besides the pose (fixed for a trial).
#[derive(Clone, Debug, Default)]
pub struct Context {
    pub route: Route,
    /// World scale s: lengths scale with s, speeds with √s.
    pub scale: f64,
    /// Tracking lookahead at full scale, m.
    pub lookahead: f64,
    pub max_steer: f64,
}

/// Segments of `seg_ticks` control ticks each.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    pub segments: Vec<Segment>,
}

impl Plan {
    /// The segment in force `tick` control ticks after the plan started (the last one beyond).
    pub fn at(&self, tick: usize, seg_ticks: usize) -> Segment {
        let i = (tick / seg_ticks.max(1)).min(self.segments.len() - 1);
        self.segments[i]
    }

    /// The action of segment `seg` for a vehicle at `trial`'s pose.
    pub fn action(seg: Segment, trial: &Trial, ctx: &Context) -> Action {
        let pose = trial.pose();
        let steering = match seg.steer {
            Steer::Fixed(s) => s,
            Steer::Track(offset) => ctx.route.track(
                pose.x,
                pose.y,
                pose.yaw,
                ctx.lookahead * ctx.scale,
                offset * ctx.scale,
                ctx.max_steer,
            ),
        };
        Action::HighLevel {
            speed: seg.speed * ctx.scale.sqrt(),
            steering,
        }
    }
}

/// Sizes and speeds of the candidate set (resolved from the parameters).
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    pub samples: usize,
    pub segments: usize,
    pub seg_ticks: usize,
    pub horizon_ticks: usize,
    pub replan_ticks: usize,
    /// Control period, s.
    pub period: f64,
    /// Nominal, lowest and highest target speed at full scale, m/s.
    pub speed: f64,
    pub min_speed: f64,
    pub max_speed: f64,
    /// Lateral offset between tracking lanes at full scale, m.
    pub lane: f64,
    /// Weight of the tilt penalty.
    pub w_tilt: f64,
}

fn uniform_plan(n: usize, speed: f64, steer: Steer) -> Plan {
    Plan {
        segments: vec![Segment { speed, steer }; n],
    }
}

/// The candidates of one planning instant, in a fixed order (ties go to the earlier one):
/// the previous best shifted by one replanning period (warm start), structured ones (track the
/// route and lanes beside it, straight, hard left and right, slow and fast), then random ones,
/// half of them perturbations of the warm start and half drawn afresh.
pub fn candidates(shape: &Shape, previous: Option<&Plan>, rng: &mut Rng) -> Vec<Plan> {
    let n = shape.segments;
    let (v, lane) = (shape.speed, shape.lane);
    let mut out = Vec::with_capacity(shape.samples + 12);
    let warm = previous.map(|p| Plan {
        segments: (0..n)
            .map(|i| p.at(i * shape.seg_ticks + shape.replan_ticks, shape.seg_ticks))
            .collect(),
    });
    if let Some(w) = &warm {
        out.push(w.clone());
    }
    out.push(uniform_plan(n, v, Steer::Track(0.0)));
    for o in [lane, -lane, 2.0 * lane, -2.0 * lane] {
        out.push(uniform_plan(n, v, Steer::Track(o)));
    }
    out.push(uniform_plan(n, v, Steer::Fixed(0.0)));
    for s in [1.0, -1.0] {
        let mut p = uniform_plan(n, v, Steer::Track(0.0));
        p.segments[0].steer = Steer::Fixed(s);
        out.push(p);
    }
    out.push(uniform_plan(n, shape.min_speed, Steer::Track(0.0)));
    out.push(uniform_plan(n, shape.max_speed, Steer::Track(0.0)));
    out.truncate(shape.samples);
    let mut k = 0;
    while out.len() < shape.samples {
        let base = warm.as_ref().filter(|_| k % 2 == 0);
        let segments = (0..n)
            .map(|i| match base {
                Some(b) => perturb(b.segments[i], shape, rng),
                None => random_segment(shape, rng),
            })
            .collect();
        out.push(Plan { segments });
        k += 1;
    }
    out
}

fn random_segment(shape: &Shape, rng: &mut Rng) -> Segment {
    let speed = rng.range(shape.min_speed, shape.max_speed);
    let steer = if rng.uniform() < 0.5 {
        Steer::Fixed(rng.range(-1.0, 1.0))
    } else {
        Steer::Track(rng.range(-2.0 * shape.lane, 2.0 * shape.lane))
    };
    Segment { speed, steer }
}

fn perturb(s: Segment, shape: &Shape, rng: &mut Rng) -> Segment {
    let speed = (s.speed + rng.gauss(0.0, 0.5)).clamp(shape.min_speed, shape.max_speed);
    let steer = match s.steer {
        Steer::Fixed(x) => Steer::Fixed((x + rng.gauss(0.0, 0.3)).clamp(-1.0, 1.0)),
        Steer::Track(o) => Steer::Track(
            (o + rng.gauss(0.0, 0.5 * shape.lane)).clamp(-3.0 * shape.lane, 3.0 * shape.lane),
        ),
    };
    Segment { speed, steer }
}

/// Score of reaching the goal inside the horizon, and of a failure there, in metres of
/// progress: larger than any progress a horizon can make, so reaching the goal always wins and
/// a failure always loses.
const SUCCESS_BONUS: f64 = 1000.0;
const FAILURE_PENALTY: f64 = 1000.0;
/// |roll| beyond which a vehicle is taken as lost even if it has not capsized yet: past it,
/// a trial that then stops is classed a rollover (30°), and none of the vehicles recovers
/// reliably.
const ROLL_LOST_DEG: f64 = 40.0;
/// Where the tilt penalty starts, degrees.
const ROLL_SOFT_DEG: f64 = 15.0;
const PITCH_SOFT_DEG: f64 = 20.0;

/// What a rollout found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rollout {
    pub score: f64,
    /// How the branch ended inside the horizon, and after how many ticks.
    pub ended: Option<(Outcome, usize)>,
}

/// Rolls `plan` out on a branch of `trial` over the horizon and scores it: the decrease of the
/// route's cost-to-go (full-scale metres; in effect the planar distance to the goal, see
/// [`super::route`]), a bonus for reaching the goal (earlier is better),
/// penalties for failing (rollover, stuck, error), leaving the map or tilting past the lost
/// roll, a mild quadratic penalty on roll and pitch beyond their soft limits, and a little
/// for the speed kept at the end (a vehicle that stops on a slope often cannot start again).
pub fn rollout(trial: &Trial, plan: &Plan, shape: &Shape, ctx: &Context) -> Rollout {
    let mut b = trial.branch();
    let s = ctx.scale;
    let start = b.pose();
    let g0 = ctx.route.cost_to_go(start.x, start.y);
    let world = b.world().clone();
    let terrain = &world.terrain;
    let mut tilt = 0.0;
    let mut lost = false;
    let mut off_map = false;
    let mut ended = None;
    for tick in 0..shape.horizon_ticks {
        let a = Plan::action(plan.at(tick, shape.seg_ticks), &b, ctx);
        let out = b.step(a, shape.period);
        let p = b.pose();
        let roll = p.roll.to_degrees().abs();
        let pitch = p.pitch.to_degrees().abs();
        tilt += ((roll - ROLL_SOFT_DEG).max(0.0).powi(2)
            + (pitch - PITCH_SOFT_DEG).max(0.0).powi(2))
            / 100.0;
        lost |= roll > ROLL_LOST_DEG;
        if !terrain.contains(p.x, p.y) {
            off_map = true;
            break;
        }
        if let Some(o) = out.ended {
            ended = Some((o, tick + 1));
            break;
        }
    }
    let end = b.pose();
    let progress = (g0 - ctx.route.cost_to_go(end.x, end.y)) / s;
    let horizon = shape.horizon_ticks as f64 * shape.period;
    let mut score = progress - shape.w_tilt * tilt
        + 0.5 * (b.state().forward_speed() / s.sqrt()).clamp(-5.0, 5.0);
    match ended {
        Some((Outcome::Success, t)) => {
            score += SUCCESS_BONUS + shape.max_speed * (horizon - t as f64 * shape.period);
        }
        // a later failure leaves more room to avoid it at the next plan
        Some((Outcome::Rollover | Outcome::Stuck | Outcome::Error, t)) => {
            score -= FAILURE_PENALTY * (1.0 - 0.5 * t as f64 * shape.period / horizon);
        }
        // the time limit is the same for every candidate: progress decides
        Some((Outcome::Timeout, _)) | None => {}
    }
    if off_map {
        score -= FAILURE_PENALTY;
    }
    if lost && !matches!(ended, Some((Outcome::Success, _))) {
        score -= 0.5 * FAILURE_PENALTY;
    }
    Rollout { score, ended }
}
