//! A recording is the evaluated trial, sampled: same result, one frame per control period.

use std::sync::Arc;
use verti_bench::{Action, EpisodeConfig, MobilitySystem, Observation, TaskInfo, run_episode};

/// Drives straight at 2 m/s with a little steering: enough to move wheels and suspension.
struct Steady;
impl MobilitySystem for Steady {
    fn name(&self) -> &str {
        "steady"
    }
    fn control_rate(&self) -> f64 {
        10.0
    }
    fn reset(&mut self, _task: &TaskInfo) {}
    fn act(&mut self, _obs: &Observation) -> Action {
        Action::HighLevel {
            speed: 2.0,
            steering: 0.2,
        }
    }
}

fn json_without_wall_time(r: &verti_bench::TrialResult) -> String {
    let mut r = r.clone();
    r.wall_time = 0.0;
    serde_json::to_string(&r).unwrap()
}

#[test]
fn a_recording_samples_the_evaluated_trial() {
    let set = verti_world::sets::resolve_set("verti-4", 1.0, &|| {}).unwrap();
    let world = Arc::new(set.worlds.into_iter().next().unwrap());
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let cfg = EpisodeConfig {
        max_time: 4.0,
        ..Default::default()
    };
    let pair = world.tasks[0].pair;
    let (rec, result) = verti_view::record_trial(&world, &spec, pair, &mut Steady, &cfg);
    let plain = run_episode(&world, &spec, pair, &mut Steady, &cfg, None);
    // watching changes nothing
    assert_eq!(
        json_without_wall_time(&result),
        json_without_wall_time(&plain)
    );
    // the start and one frame per 0.1-s control period up to the 4-s limit
    assert_eq!(rec.frames.len(), 41, "{}", rec.frames.len());
    assert!(rec.frames.windows(2).all(|w| w[1].t > w[0].t));
    assert!((rec.frames.last().unwrap().t - 4.0).abs() < 1e-6);
    assert!(rec.frames.iter().all(|f| f.wheels.len() == 4));
    assert_eq!(rec.wheel_size.len(), 4);
    assert_eq!(rec.heights.len(), rec.n * rec.n);
    assert_eq!(rec.colors.len(), rec.n * rec.n);
    // the vehicle moved, steered its front wheels and worked its suspension
    let (a, b) = (&rec.frames[0], rec.frames.last().unwrap());
    assert!((b.body[0] - a.body[0]).hypot(b.body[1] - a.body[1]) > 2.0);
    assert!(
        b.wheels[0][3].abs() > 0.01 && b.wheels[2][3].abs() < 1e-6,
        "{:?}",
        b.wheels
    );
    assert!(
        rec.frames
            .iter()
            .any(|f| (f.wheels[0][4] - a.wheels[0][4]).abs() > 1e-4)
    );

    // the page carries the recording whole, and nothing in it can close the script early
    let html = verti_view::html(&rec);
    let open = "<script id=\"data\" type=\"application/json\">";
    let start = html.find(open).unwrap() + open.len();
    let end = start + html[start..].find("</script>").unwrap();
    let back: verti_view::Recording = serde_json::from_str(&html[start..end]).unwrap();
    assert_eq!(back.frames.len(), rec.frames.len());
    assert_eq!(back.title, rec.title);
    assert!(!html.contains("/*VERTI_DATA*/"));
}

/// Names are the user's: `<!--<script>` in one put the HTML parser in the script-data escaped
/// state, where one `</script>` no longer ends the data block, and the page broke (issue 33,
/// item 10). No `<` may be left in the data block; the names still read back exactly.
#[test]
fn no_name_can_end_the_data_block_early() {
    let set = verti_world::sets::resolve_set("verti-4", 1.0, &|| {}).unwrap();
    let world = Arc::new(set.worlds.into_iter().next().unwrap());
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let cfg = EpisodeConfig {
        max_time: 0.2,
        ..Default::default()
    };
    let pair = world.tasks[0].pair;
    let (mut rec, _) = verti_view::record_trial(&world, &spec, pair, &mut Steady, &cfg);
    let hostile = "w <!--<script> </script> <!-- --> & \u{2028} \"x\" \\ end";
    rec.title = hostile.to_string();
    let html = verti_view::html(&rec);
    let open = "<script id=\"data\" type=\"application/json\">";
    let start = html.find(open).unwrap() + open.len();
    let end = start + html[start..].find("</script>").unwrap();
    let block = &html[start..end];
    assert!(
        !block.contains('<') && !block.contains('>'),
        "the data block holds markup"
    );
    let back: verti_view::Recording = serde_json::from_str(block).unwrap();
    assert_eq!(back.title, hostile);
    // the page's own script follows the data block intact
    assert!(html[end..].starts_with("</script>\n<script>\n\"use strict\";"));
}
