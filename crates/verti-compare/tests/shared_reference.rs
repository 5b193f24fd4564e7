//! The Chrono reference in ../shared reads, and two of its tasks re-run end to end (the data is not part of the repository; the tests say so and pass when it is
//! absent).

use std::path::PathBuf;
use verti_compare::reference::trajectory_file_name;
use verti_compare::{
    CompareSetup, compare_task, load_worlds, read_reference, run_tasks, select_tasks, summarize,
};
use verti_world::TerrainType;

fn shared() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared");
    let ok = dir.join("chrono-reference").is_dir() && dir.join("verti-bench-data/worlds").is_dir();
    if !ok {
        eprintln!(
            "SKIPPED: {} lacks chrono-reference or verti-bench-data; comparison checks not run",
            dir.display()
        );
    }
    ok.then_some(dir)
}

#[test]
fn the_shared_reference_reads_completely() {
    let Some(dir) = shared() else { return };
    let r = read_reference(&dir.join("chrono-reference")).unwrap();
    assert_eq!(r.tasks.len(), 31);
    for t in &r.tasks {
        let o = &t.outcome;
        let name = trajectory_file_name(o.world_index, o.pair);
        let last = t.trajectory.last().expect(&name);
        // 10 Hz samples up to the end of the trial
        assert!(
            last.t <= o.time + 1e-9 && o.time - last.t < 0.1 + 1e-9,
            "{name}: last sample {} for a trial of {} s",
            last.t,
            o.time
        );
        assert!(
            o.world.starts_with(&format!("vb/config{}_", o.world_index)),
            "{}",
            o.world
        );
    }
}

#[test]
fn two_tasks_rerun_and_compare() {
    let Some(dir) = shared() else { return };
    let reference = read_reference(&dir.join("chrono-reference")).unwrap();
    let outcomes: Vec<_> = reference.tasks.iter().map(|t| t.outcome.clone()).collect();
    // a low-elevation success and the high-elevation task Chrono rolls over after 8.6 s
    let chosen = select_tasks(&outcomes, "9:0,2:0").unwrap();
    let setup = CompareSetup::reference(verti_sim::vehicles::builtin("hmmwv").unwrap());
    let refs: Vec<_> = chosen.iter().map(|&i| &outcomes[i]).collect();
    let worlds = load_worlds(
        &dir.join("verti-bench-data/worlds"),
        &dir.join("chrono-reference"),
        &refs,
        &setup,
    )
    .unwrap();
    assert_eq!(worlds.len(), 2);
    for w in worlds.values() {
        assert_eq!(w.meta.terrain_type, TerrainType::Rigid);
        assert!(w.labels().iter().all(|&l| l == 2));
    }
    let tasks: Vec<(u32, u32)> = refs.iter().map(|o| (o.world_index, o.pair)).collect();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let runs = run_tasks(&worlds, &tasks, &setup, 2, &|| {
        done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap();
    assert_eq!((runs.len(), done.into_inner()), (2, 2));
    // deterministic whatever the number of threads (wall time aside)
    let again = run_tasks(&worlds, &tasks, &setup, 1, &|| {}).unwrap();
    for (a, b) in runs.iter().zip(&again) {
        // (agl is NaN in verti's samples, and NaN != NaN)
        let pose = |r: &verti_compare::VertiRun| -> Vec<[f64; 7]> {
            r.samples
                .iter()
                .map(|s| [s.t, s.x, s.y, s.z, s.roll, s.pitch, s.yaw])
                .collect()
        };
        assert_eq!(pose(a), pose(b));
        assert_eq!(a.result.outcome, b.result.outcome);
    }
    let comparisons: Vec<_> = chosen
        .iter()
        .zip(&runs)
        .map(|(&i, run)| {
            // 10 Hz samples over the trial
            let n = (run.result.time / 0.1 + 1e-6).floor() as usize;
            assert_eq!(run.samples.len(), n, "{:?}", run.result);
            assert!((run.samples[0].t - 0.1).abs() < 1e-9);
            compare_task(&reference.tasks[i], run)
        })
        .collect();
    for c in &comparisons {
        assert!(c.early.common_samples > 0 && c.early.common_samples <= c.early.samples);
    }
    // both engines start at the same place on the same path: on the low-elevation task, where
    // nothing tips or stops, the early divergence is small (the high one ends in a rollover
    // within seconds, which throws the vehicle sideways in either engine)
    for c in comparisons.iter().filter(|c| c.world_index == 9) {
        assert!(
            c.early.mean_lateral < 2.0,
            "{} pair {}: {:?}",
            c.world,
            c.pair,
            c.early
        );
    }
    let s = summarize(&setup, &reference.tasks[0].outcome.engine, comparisons);
    assert_eq!(s.groups[0].tasks, 2);
    let md = verti_compare::markdown::markdown(&s);
    assert!(md.contains("| all tasks | 2 |"), "{md}");
    let json = serde_json::to_string(&s).unwrap();
    assert!(json.contains("\"engine\":\"chrono-9.0.1\""));
}

/// The soil and sections sets: each task's line names its ground, and the worlds are prepared
/// for it (issue 34): single-soil worlds as imported, sections with their frictions.
#[test]
fn soil_and_sections_worlds_are_prepared_for_their_ground() {
    use verti_compare::reference::RefGround;
    use verti_world::{Surface, TerrainClass};
    let Some(dir) = shared() else { return };
    let setup = CompareSetup::reference(verti_sim::vehicles::builtin("hmmwv").unwrap());
    let vb = dir.join("verti-bench-data/worlds");

    let soil_dir = dir.join("chrono-reference/soil");
    let soil = read_reference(&soil_dir).unwrap();
    assert_eq!(soil.tasks.len(), 90);
    let outcomes: Vec<_> = soil.tasks.iter().map(|t| t.outcome.clone()).collect();
    let chosen = select_tasks(&outcomes, "82:0,62:0").unwrap();
    let refs: Vec<_> = chosen.iter().map(|&i| &outcomes[i]).collect();
    let on = |w: u32| refs.iter().find(|o| o.world_index == w).unwrap().ground;
    assert_eq!(on(82), RefGround::Soil(TerrainClass::Snow));
    assert_eq!(on(62), RefGround::Soil(TerrainClass::Sand));
    let worlds = load_worlds(&vb, &soil_dir, &refs, &setup).unwrap();
    let snow = &worlds[&82];
    assert_eq!(snow.meta.terrain_type, TerrainType::Deformable);
    assert!(snow.patches.patches().iter().all(|p| p.class == TerrainClass::Snow
        && matches!(p.surface, Surface::Deformable { soil } if soil == verti_world::SoilParams::SOFT)));
    assert!(
        worlds[&62]
            .patches
            .patches()
            .iter()
            .all(|p| p.class == TerrainClass::Sand)
    );

    let sections_dir = dir.join("chrono-reference/sections");
    let sections = read_reference(&sections_dir).unwrap();
    let outcomes: Vec<_> = sections.tasks.iter().map(|t| t.outcome.clone()).collect();
    let chosen = select_tasks(&outcomes, "1:0").unwrap();
    let refs: Vec<_> = chosen.iter().map(|&i| &outcomes[i]).collect();
    assert_eq!(refs[0].ground, RefGround::Sections);
    let worlds = load_worlds(&vb, &sections_dir, &refs, &setup).unwrap();
    // the first section of world 1 (patch rows 0-2, columns 0-4) has friction 0.6245...
    let p = worlds[&1].patches.patches()[2 * 16 + 4];
    assert!(
        matches!(p.surface, Surface::Rigid { friction, .. } if (friction - 0.6245413657884453).abs() < 1e-15),
        "{p:?}"
    );
    // and the worlds of a set with a missing section file are named
    let err = load_worlds(&vb, &dir.join("chrono-reference"), &refs, &setup).unwrap_err();
    assert!(err.to_string().contains("world-001.tsv"), "{err}");
}
