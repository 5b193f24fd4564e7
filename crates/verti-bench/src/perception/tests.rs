//! Noise statistics against their parameters, on worlds where the answer is known.

use super::*;
use crate::features::FeatureSource;
use verti_sim::testing;

fn mean_std(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let m = xs.iter().sum::<f64>() / n;
    let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, v.sqrt())
}

fn only(f: impl FnOnce(&mut PerceptionModel)) -> Arc<PerceptionModel> {
    let mut m = PerceptionModel::none();
    f(&mut m);
    m.validate().unwrap();
    Arc::new(m)
}

#[test]
fn height_noise_has_its_sigma_and_no_bias() {
    let world = testing::plane_world(1.0, 0.0, 0.0, 0.8);
    let m = only(|m| m.elevation.sigma = 0.1);
    let p = Perception::new(&world, m, 7);
    let err: Vec<f64> = p
        .world()
        .terrain
        .heights()
        .iter()
        .zip(world.terrain.heights())
        .map(|(a, b)| a - b)
        .collect();
    let (mean, std) = mean_std(&err);
    // thousands of vertices: the sample std is within a few % of 0.1
    assert!(err.len() > 1000, "{}", err.len());
    assert!(
        mean.abs() < 0.01 && (std - 0.1).abs() < 0.01,
        "{mean} {std}"
    );
}

#[test]
fn holes_are_in_painted_from_neighbours() {
    // a plane tilted 0.1 m/m: a hole filled by the mean of its neighbours is exact on a plane
    let world = testing::plane_world(1.0, 0.1f64.atan(), 0.0, 0.8);
    let m = only(|m| m.elevation.hole_fraction = 0.3);
    let p = Perception::new(&world, m, 3);
    let worst = p
        .world()
        .terrain
        .heights()
        .iter()
        .zip(world.terrain.heights())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    // interior holes are exact; edge holes average a one-sided neighbourhood (off by at most
    // about one cell's rise)
    assert!(worst < 0.1 * world.terrain.cell() + 1e-9, "{worst}");
}

#[test]
fn drift_grows_as_a_random_walk() {
    let world = testing::plane_world(1.0, 0.0, 0.0, 0.8);
    let m = only(|m| m.pose.position_drift = 0.2);
    // after T seconds a random walk of drift q has std q·√T per axis
    let (steps, dt) = (400, 0.05);
    let finals: Vec<f64> = (0..400)
        .map(|seed| {
            let mut p = Perception::new(&world, m.clone(), seed);
            for _ in 0..steps {
                p.advance(dt);
            }
            p.drift()[0]
        })
        .collect();
    let (mean, std) = mean_std(&finals);
    let expected = 0.2 * (steps as f64 * dt).sqrt();
    assert!(mean.abs() < 0.2 * expected, "{mean}");
    assert!((std / expected - 1.0).abs() < 0.12, "{std} vs {expected}");
}

#[test]
fn white_pose_noise_matches_sigma_and_is_redrawn() {
    let world = testing::plane_world(1.0, 0.0, 0.0, 0.8);
    let m = only(|m| {
        m.pose.yaw_sigma_deg = 2.0;
        m.velocity.linear_sigma = 0.3;
    });
    let truth = FeatureSource::at_rest(Pose6::default());
    let mut p = Perception::new(&world, m, 11);
    let (mut yaw, mut vx) = (Vec::new(), Vec::new());
    for _ in 0..4000 {
        let seen = p.estimate(&truth);
        yaw.push(seen.pose.yaw.to_degrees());
        vx.push(seen.velocity_body.x);
        assert_eq!(seen.forward_speed, seen.velocity_body.x);
        // nothing else moves
        assert_eq!((seen.pose.x, seen.pose.roll), (0.0, 0.0));
        p.advance(0.05);
    }
    let (ym, ys) = mean_std(&yaw);
    let (vm, vs) = mean_std(&vx);
    assert!(ym.abs() < 0.1 && (ys - 2.0).abs() < 0.1, "{ym} {ys}");
    assert!(vm.abs() < 0.02 && (vs - 0.3).abs() < 0.015, "{vm} {vs}");
}

#[test]
fn map_only_noise_leaves_the_state_estimate_exact() {
    // re-wrapping a yaw moves its last bit for most angles, which is enough to change a
    // chaotic trial: a model that perturbs only the map must hand the true state through
    let world = testing::plane_world(1.0, 0.0, 0.0, 0.8);
    let m = only(|m| {
        m.elevation.sigma = 0.1;
        m.obstacles.miss_probability = 0.5;
    });
    assert!(m.exact_state() && !m.is_none());
    let yaws = [0.1, 1.0, -2.5, 3.0];
    assert!(
        yaws.iter().any(|&y| wrap(y) != y),
        "the check needs a yaw that wrapping moves"
    );
    let mut p = Perception::new(&world, m, 2);
    for yaw in yaws {
        let mut truth = FeatureSource::at_rest(Pose6::default());
        truth.pose.yaw = yaw;
        truth.pose.x = 1.25;
        // bit for bit: the Debug form prints every float exactly (shortest round trip)
        assert_eq!(format!("{:?}", p.estimate(&truth)), format!("{truth:?}"));
        p.advance(0.05);
    }
    assert!(!only(|m| m.pose.yaw_drift_deg = 0.1).exact_state());
    assert!(!only(|m| m.velocity.linear_sigma = 0.1).exact_state());
}

#[test]
fn class_confusion_follows_its_rate() {
    let world = testing::plane_world(1.0, 0.0, 0.0, 0.8);
    let m = only(|m| m.semantics.confusion = 0.25);
    let (mut changed, mut total) = (0usize, 0usize);
    for seed in 0..40 {
        let p = Perception::new(&world, m.clone(), seed);
        for (a, b) in p
            .world()
            .patches
            .patches()
            .iter()
            .zip(world.patches.patches())
        {
            total += 1;
            if a.class != b.class {
                changed += 1;
                // a confused patch carries the physics of the class it is seen as
                if let Some((mu, _)) = a.class.friction_distribution() {
                    assert_eq!(a.surface.effective_friction(), mu);
                }
            }
        }
    }
    let rate = changed as f64 / total as f64;
    // 40 x 256 patches: binomial std ~0.004
    assert!((rate - 0.25).abs() < 0.015, "{rate}");
}

#[test]
fn obstacles_are_missed_and_invented_at_their_rates() {
    let world = testing::plane_world(1.0, 0.0, 0.0, 0.8);
    let area_ha = (2.0 * world.terrain.half_extent()).powi(2) / 10_000.0;
    let m = only(|m| m.obstacles.false_per_hectare = 5.0);
    let counts: Vec<f64> = (0..3000)
        .map(|s| {
            Perception::new(&world, m.clone(), s)
                .world()
                .obstacles
                .len() as f64
        })
        .collect();
    let (mean, std) = mean_std(&counts);
    let expected = 5.0 * area_ha;
    // misses: 400 trees, each missed with probability 0.3
    let mut trees = world.clone();
    trees.obstacles = (0..400)
        .map(|i| {
            let p = verti_core::Vec3::new(f64::from(i % 20) * 2.0 - 20.0, f64::from(i / 20), 1.0);
            verti_world::Obstacle::tree(0.2, 2.0, p).unwrap()
        })
        .collect();
    let m = only(|m| m.obstacles.miss_probability = 0.3);
    let seen: usize = (0..20)
        .map(|s| {
            Perception::new(&trees, m.clone(), s)
                .world()
                .obstacles
                .len()
        })
        .sum();
    let rate = seen as f64 / 8000.0;
    // binomial std ~0.005
    assert!((rate - 0.7).abs() < 0.02, "{rate}");
    // Poisson: mean = variance
    assert!((mean / expected - 1.0).abs() < 0.1, "{mean} vs {expected}");
    assert!(
        (std * std / expected - 1.0).abs() < 0.25,
        "{std} {mean} {expected}"
    );
}

#[test]
fn the_same_seed_gives_the_same_perception() {
    let world = testing::plane_world(1.0, 0.05, 0.02, 0.8);
    let m = Arc::new(PerceptionModel::preset("high").unwrap());
    let mut a = Perception::new(&world, m.clone(), 5);
    let mut b = a.clone();
    for _ in 0..10 {
        a.advance(0.05);
        b.advance(0.05);
    }
    let truth = FeatureSource::at_rest(Pose6::default());
    assert_eq!(
        format!("{:?}", a.estimate(&truth)),
        format!("{:?}", b.estimate(&truth))
    );
    let c = Perception::new(&world, m, 5);
    assert_eq!(
        c.world().terrain,
        Perception::new(&world, c.model.clone(), 5).world().terrain
    );
    assert_ne!(
        c.world().terrain,
        Perception::new(&world, c.model.clone(), 6).world().terrain
    );
}

#[test]
fn sensing_limits_range_and_shifts_by_latency() {
    let world = testing::plane_world(1.0, 0.0, 0.0, 0.8);
    let m = only(|m| {
        m.elevation.range = 10.0;
        m.elevation.latency = 0.5;
    });
    let p = Perception::new(&world, m, 1);
    let pose = Pose6 {
        yaw: std::f64::consts::FRAC_PI_2,
        ..Default::default()
    };
    let s = p.sensing(&pose, 4.0);
    assert!(s.sees(0.0, 9.9) && !s.sees(0.0, 10.1));
    // 4 m/s x 0.5 s = 2 m along the heading (north)
    let (x, y) = s.lookup(1.0, 5.0);
    assert!((x - 1.0).abs() < 1e-12 && (y - 3.0).abs() < 1e-12);
}
