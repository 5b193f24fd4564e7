//! Reading reference runs: `outcomes.jsonl` (one JSON object per task) and
//! `trajectories/world-NNN_pP.csv` (10 Hz samples), as `../shared/chrono-reference` holds them.
//!
//! Only the fields the comparison uses are required; the others are kept when present, since
//! reference sets made later may leave some out.

use crate::error::{CompareError, Result};
use serde::Serialize;
use serde_json::{Map, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use verti_bench::Outcome;

/// The outcomes file of a reference folder.
pub const OUTCOMES_FILE: &str = "outcomes.jsonl";
/// The folder of trajectory files inside a reference folder.
pub const TRAJECTORIES_DIR: &str = "trajectories";

/// Name of the trajectory file of a task: `world-002_p3.csv`.
pub fn trajectory_file_name(world_index: u32, pair: u32) -> String {
    format!("world-{world_index:03}_p{pair}.csv")
}

/// The ground a reference task was run on (the outcome line's `soil` field).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RefGround {
    /// No `soil` field: rigid ground with one friction everywhere (the first reference set).
    OneFriction,
    /// `snow`, `mud` or `sand`: one SCM soil over the whole map, the world's own (the
    /// single-soil deformable worlds, compared as imported).
    Soil(verti_world::TerrainClass),
    /// `rigid-sections`: rigid ground built from the reference's friction sections
    /// (`frictions/world-NNN.tsv` in the reference folder).
    Sections,
}

impl RefGround {
    /// The name in outcome lines and summaries.
    pub fn name(self) -> String {
        match self {
            RefGround::OneFriction => "one-friction".into(),
            RefGround::Soil(class) => class.to_string(),
            RefGround::Sections => "rigid-sections".into(),
        }
    }

    fn parse(text: Option<&str>) -> Result<RefGround, String> {
        use verti_world::TerrainClass;
        Ok(match text {
            None => RefGround::OneFriction,
            Some("rigid-sections") => RefGround::Sections,
            Some("snow") => RefGround::Soil(TerrainClass::Snow),
            Some("mud") => RefGround::Soil(TerrainClass::Mud),
            Some("sand") => RefGround::Soil(TerrainClass::Sand),
            Some(other) => {
                return Err(format!(
                    "field `soil`: `{other}` is not one of snow, mud, sand, rigid-sections"
                ));
            }
        })
    }
}

/// One line of `outcomes.jsonl`: how the reference engine's trial of one task ended.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RefOutcome {
    /// Engine and version, e.g. `chrono-9.0.1` (`reference` when absent).
    pub engine: String,
    /// World name as verti imports it, `vb/configN_LEVEL`.
    pub world: String,
    pub world_index: u32,
    pub pair: u32,
    pub outcome: Outcome,
    /// Simulated seconds at the end of the trial.
    pub time: f64,
    pub traversal_time: Option<f64>,
    pub final_distance: Option<f64>,
    /// Degrees over the trial.
    pub mean_abs_roll: f64,
    pub max_abs_roll: f64,
    pub mean_abs_pitch: f64,
    pub max_abs_pitch: f64,
    pub final_roll: Option<f64>,
    pub path_length: Option<f64>,
    /// Real-time factor of the reference engine (simulated / wall seconds).
    pub rtf: Option<f64>,
    /// The ground the task was run on.
    pub ground: RefGround,
    /// Line of the outcomes file (1-based), for messages.
    pub line: usize,
}

/// One trajectory sample. Angles in degrees; values a source does not record are NaN.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Sample {
    pub t: f64,
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub roll: f64,
    pub pitch: f64,
    pub yaw: f64,
    /// Forward speed, m/s.
    pub v: f64,
    pub steer: f64,
    pub throttle: f64,
    pub brake: f64,
    /// Height of the chassis reference above the ground, m.
    pub agl: f64,
}

impl Sample {
    /// A sample with only time and pose known.
    pub fn pose(t: f64, x: f64, y: f64, roll: f64, pitch: f64) -> Sample {
        Sample {
            t,
            x,
            y,
            z: f64::NAN,
            roll,
            pitch,
            yaw: f64::NAN,
            v: f64::NAN,
            steer: f64::NAN,
            throttle: f64::NAN,
            brake: f64::NAN,
            agl: f64::NAN,
        }
    }
}

/// One reference task: its outcome and its trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct RefTask {
    pub outcome: RefOutcome,
    pub trajectory: Vec<Sample>,
}

/// A reference folder, read and checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    pub dir: PathBuf,
    /// In the order of the outcomes file.
    pub tasks: Vec<RefTask>,
}

/// Reads `dir/outcomes.jsonl` and every task's trajectory.
pub fn read_reference(dir: &Path) -> Result<Reference> {
    if !dir.is_dir() {
        return Err(CompareError::Argument(format!(
            "{}: no such reference folder (it should hold {OUTCOMES_FILE} and {TRAJECTORIES_DIR}/)",
            dir.display()
        )));
    }
    let outcomes = read_outcomes(&dir.join(OUTCOMES_FILE))?;
    let tasks = outcomes
        .into_iter()
        .map(|outcome| {
            let path = dir
                .join(TRAJECTORIES_DIR)
                .join(trajectory_file_name(outcome.world_index, outcome.pair));
            let trajectory = read_trajectory(&path)?;
            Ok(RefTask {
                outcome,
                trajectory,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Reference {
        dir: dir.to_path_buf(),
        tasks,
    })
}

fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| CompareError::io(path, e))
}

/// Reads an outcomes file (see [`parse_outcomes`]).
pub fn read_outcomes(path: &Path) -> Result<Vec<RefOutcome>> {
    parse_outcomes(&read_text(path)?, path)
}

/// Parses the lines of an outcomes file; `path` is for messages. Blank lines are skipped. A
/// task (world index and pair) given twice is refused, naming both lines.
pub fn parse_outcomes(text: &str, path: &Path) -> Result<Vec<RefOutcome>> {
    let mut out = Vec::new();
    let mut seen: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        if raw.trim().is_empty() {
            continue;
        }
        let err = |problem: String| CompareError::line(path, line, problem);
        let value: Value =
            serde_json::from_str(raw).map_err(|e| err(format!("not a JSON object: {e}")))?;
        let Value::Object(obj) = value else {
            return Err(err("not a JSON object".into()));
        };
        let o = parse_outcome(&obj, line).map_err(err)?;
        if let Some(first) = seen.insert((o.world_index, o.pair), line) {
            return Err(err(format!(
                "world {} pair {} is already given on line {first}",
                o.world_index, o.pair
            )));
        }
        out.push(o);
    }
    if out.is_empty() {
        return Err(CompareError::Argument(format!(
            "{}: no reference tasks in the file",
            path.display()
        )));
    }
    Ok(out)
}

fn parse_outcome(obj: &Map<String, Value>, line: usize) -> Result<RefOutcome, String> {
    let field = |name: &str| obj.get(name).filter(|v| !v.is_null());
    let number = |name: &str| -> Result<Option<f64>, String> {
        match field(name) {
            None => Ok(None),
            Some(v) => v
                .as_f64()
                .filter(|x| x.is_finite())
                .map(Some)
                .ok_or_else(|| format!("field `{name}`: {v} is not a finite number")),
        }
    };
    let required = |name: &str| -> Result<f64, String> {
        number(name)?.ok_or_else(|| format!("field `{name}` is missing"))
    };
    let index = |name: &str| -> Result<u32, String> {
        let v = field(name).ok_or_else(|| format!("field `{name}` is missing"))?;
        v.as_u64()
            .and_then(|n| u32::try_from(n).ok())
            .ok_or_else(|| format!("field `{name}`: {v} is not a non-negative integer"))
    };
    let text = |name: &str| -> Result<Option<String>, String> {
        match field(name) {
            None => Ok(None),
            Some(Value::String(s)) => Ok(Some(s.clone())),
            Some(v) => Err(format!("field `{name}`: {v} is not a string")),
        }
    };
    let outcome_name = text("outcome")?.ok_or("field `outcome` is missing")?;
    let outcome = Outcome::ALL
        .into_iter()
        .find(|o| o.name() == outcome_name)
        .ok_or_else(|| {
            format!(
                "field `outcome`: `{outcome_name}` is not one of success, rollover, stuck, timeout, error"
            )
        })?;
    let world = text("world")?.ok_or("field `world` is missing")?;
    let world_index = index("world_index")?;
    if world_index == 0 {
        return Err("field `world_index`: world indices start at 1".into());
    }
    let o = RefOutcome {
        engine: text("engine")?.unwrap_or_else(|| "reference".into()),
        world,
        world_index,
        pair: index("pair")?,
        outcome,
        time: required("time")?,
        traversal_time: number("traversal_time")?,
        final_distance: number("final_distance")?,
        mean_abs_roll: required("mean_abs_roll")?,
        max_abs_roll: required("max_abs_roll")?,
        mean_abs_pitch: required("mean_abs_pitch")?,
        max_abs_pitch: required("max_abs_pitch")?,
        final_roll: number("final_roll")?,
        path_length: number("path_length")?,
        rtf: number("rtf")?,
        ground: RefGround::parse(text("soil")?.as_deref())?,
        line,
    };
    if o.time < 0.0 {
        return Err(format!("field `time`: {} is negative", o.time));
    }
    if o.outcome == Outcome::Success && o.traversal_time.is_none() {
        return Err("field `traversal_time` is missing for a success".into());
    }
    Ok(o)
}

/// The columns a trajectory must have, in the order of [`Sample`].
const REQUIRED_COLUMNS: [&str; 7] = ["t", "x", "y", "z", "roll", "pitch", "yaw"];
/// Columns read when present.
const OPTIONAL_COLUMNS: [&str; 5] = ["v", "steer", "throttle", "brake", "agl"];

/// A sample's values in the order of [`REQUIRED_COLUMNS`] then [`OPTIONAL_COLUMNS`] (the
/// writer's order; [`sample_from_values`] is the reader's).
fn sample_values(s: &Sample) -> [f64; 12] {
    [
        s.t, s.x, s.y, s.z, s.roll, s.pitch, s.yaw, s.v, s.steer, s.throttle, s.brake, s.agl,
    ]
}

/// The sample whose values, in [`sample_values`]' order, are `v`.
fn sample_from_values(v: [f64; 12]) -> Sample {
    let [
        t,
        x,
        y,
        z,
        roll,
        pitch,
        yaw,
        speed,
        steer,
        throttle,
        brake,
        agl,
    ] = v;
    Sample {
        t,
        x,
        y,
        z,
        roll,
        pitch,
        yaw,
        v: speed,
        steer,
        throttle,
        brake,
        agl,
    }
}

/// `samples` as a trajectory CSV that [`parse_trajectory`] reads back: the required columns and
/// every optional one that has a number in each sample (a column with a gap would not read).
pub fn format_trajectory(samples: &[Sample]) -> String {
    let names: Vec<&str> = REQUIRED_COLUMNS
        .iter()
        .chain(&OPTIONAL_COLUMNS)
        .copied()
        .collect();
    let keep: Vec<usize> = (0..names.len())
        .filter(|&k| {
            k < REQUIRED_COLUMNS.len() || samples.iter().all(|s| sample_values(s)[k].is_finite())
        })
        .collect();
    let mut out = keep.iter().map(|&k| names[k]).collect::<Vec<_>>().join(",");
    out.push('\n');
    for s in samples {
        let v = sample_values(s);
        let row: Vec<String> = keep.iter().map(|&k| format!("{:.4}", v[k])).collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

/// Reads a trajectory file (see [`parse_trajectory`]).
pub fn read_trajectory(path: &Path) -> Result<Vec<Sample>> {
    parse_trajectory(&read_text(path)?, path)
}

/// Parses a trajectory CSV with a header line; `path` is for messages. Columns may come in
/// any order; unknown ones are ignored. Times must increase strictly.
pub fn parse_trajectory(text: &str, path: &Path) -> Result<Vec<Sample>> {
    let mut lines = text.lines().enumerate();
    let header: Vec<&str> = match lines.next() {
        Some((_, h)) => h.split(',').map(str::trim).collect(),
        None => return Err(CompareError::line(path, 1, "empty file, no header line")),
    };
    let column = |name: &str| header.iter().position(|h| *h == name);
    let mut required = [0usize; REQUIRED_COLUMNS.len()];
    for (slot, name) in required.iter_mut().zip(REQUIRED_COLUMNS) {
        *slot = column(name).ok_or_else(|| {
            CompareError::line(
                path,
                1,
                format!(
                    "header has no column `{name}` (needs {})",
                    REQUIRED_COLUMNS.join(", ")
                ),
            )
        })?;
    }
    let optional = OPTIONAL_COLUMNS.map(column);
    let mut out: Vec<Sample> = Vec::new();
    for (i, raw) in lines {
        let line = i + 1;
        if raw.trim().is_empty() {
            continue;
        }
        let err = |problem: String| CompareError::line(path, line, problem);
        let fields: Vec<&str> = raw.split(',').map(str::trim).collect();
        if fields.len() != header.len() {
            return Err(err(format!(
                "{} fields, but the header has {}",
                fields.len(),
                header.len()
            )));
        }
        let value = |k: usize| -> Result<f64> {
            fields[k]
                .parse::<f64>()
                .ok()
                .filter(|v| !v.is_nan())
                .ok_or_else(|| {
                    err(format!(
                        "column `{}`: `{}` is not a number",
                        header[k], fields[k]
                    ))
                })
        };
        let r: Vec<f64> = required.iter().map(|&k| value(k)).collect::<Result<_>>()?;
        let o: Vec<f64> = optional
            .iter()
            .map(|k| k.map_or(Ok(f64::NAN), value))
            .collect::<Result<_>>()?;
        let mut values = [0.0; 12];
        values[..REQUIRED_COLUMNS.len()].copy_from_slice(&r);
        values[REQUIRED_COLUMNS.len()..].copy_from_slice(&o);
        let s = sample_from_values(values);
        if let Some(prev) = out.last()
            && s.t <= prev.t
        {
            return Err(err(format!(
                "column `t`: {} does not come after {}",
                s.t, prev.t
            )));
        }
        out.push(s);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const LINE: &str = r#"{"engine": "chrono-9.0.1", "world": "vb/config2_high", "world_index": 2, "level": "high", "pair": 3, "outcome": "success", "time": 38.45, "traversal_time": 38.45, "final_distance": 9.9, "mean_abs_roll": 9.248, "max_abs_roll": 20.0, "mean_abs_pitch": 5.585, "max_abs_pitch": 15.0, "rtf": 0.3}"#;

    fn msg(r: Result<impl std::fmt::Debug>) -> String {
        r.unwrap_err().to_string()
    }

    #[test]
    fn outcomes_parse_and_bad_lines_name_file_line_and_field() {
        let p = Path::new("ref/outcomes.jsonl");
        let text = format!("{LINE}\n\n{}\n", LINE.replace("\"pair\": 3", "\"pair\": 4"));
        let o = parse_outcomes(&text, p).unwrap();
        assert_eq!(o.len(), 2);
        assert_eq!((o[0].world_index, o[0].pair, o[0].line), (2, 3, 1));
        assert_eq!(o[1].line, 3, "blank lines count");
        assert_eq!(o[0].outcome, Outcome::Success);
        assert_eq!(o[0].traversal_time, Some(38.45));
        assert_eq!(o[0].final_roll, None);

        let bad = |from: &str, to: &str| {
            msg(parse_outcomes(
                &format!("{LINE}\n{}", LINE.replace(from, to)),
                p,
            ))
        };
        assert_eq!(
            bad("\"success\", \"time\"", "\"flipped\", \"time\""),
            "ref/outcomes.jsonl:2: field `outcome`: `flipped` is not one of success, rollover, stuck, timeout, error"
        );
        assert_eq!(
            bad("\"time\": 38.45, ", ""),
            "ref/outcomes.jsonl:2: field `time` is missing"
        );
        assert_eq!(
            bad("\"mean_abs_roll\": 9.248", "\"mean_abs_roll\": \"x\""),
            "ref/outcomes.jsonl:2: field `mean_abs_roll`: \"x\" is not a finite number"
        );
        assert!(
            bad("\"pair\": 3", "\"pair\": -1").starts_with("ref/outcomes.jsonl:2: field `pair`")
        );
        assert_eq!(
            msg(parse_outcomes(&format!("{LINE}\n{LINE}"), p)),
            "ref/outcomes.jsonl:2: world 2 pair 3 is already given on line 1"
        );
        assert!(
            msg(parse_outcomes("{\"a\": 1", p))
                .starts_with("ref/outcomes.jsonl:1: not a JSON object")
        );
        assert!(msg(parse_outcomes("\n\n", p)).contains("no reference tasks"));
    }

    #[test]
    fn a_written_trajectory_reads_back_without_its_incomplete_columns() {
        let p = Path::new("verti-world-002_p3.csv");
        let mut a = Sample::pose(0.1, 1.0, 2.0, 3.5, -4.25);
        (a.z, a.yaw, a.v, a.agl) = (4.0, 30.0, 2.5, 0.9);
        let mut b = Sample::pose(0.2, 1.5, 2.25, 3.0, -4.0);
        (b.z, b.yaw, b.v) = (4.125, 31.0, 2.75);
        let text = format_trajectory(&[a, b]);
        assert!(text.starts_with("t,x,y,z,roll,pitch,yaw,v\n"), "{text}");
        let back = parse_trajectory(&text, p).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!((back[1].t, back[1].y, back[1].pitch), (0.2, 2.25, -4.0));
        assert_eq!((back[0].v, back[1].v), (2.5, 2.75));
        assert!(back[0].agl.is_nan(), "agl has a gap, so it is left out");
    }

    #[test]
    fn trajectories_parse_by_header_and_bad_lines_name_file_and_line() {
        let p = Path::new("ref/trajectories/world-002_p3.csv");
        let text = "t,x,y,z,roll,pitch,yaw,v\n0.1,1,2,3,4,5,6,7\n0.2,1.5,2,3,4,5,6,7\n";
        let s = parse_trajectory(text, p).unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!((s[1].t, s[1].x, s[1].roll, s[1].v), (0.2, 1.5, 4.0, 7.0));
        assert!(s[0].agl.is_nan(), "absent columns are NaN");
        // columns in another order, extra columns ignored
        let s = parse_trajectory("yaw,pitch,roll,z,y,x,t,extra\n6,5,4,3,2,1,0.1,9\n", p).unwrap();
        assert_eq!((s[0].t, s[0].x, s[0].yaw), (0.1, 1.0, 6.0));

        let bad = |body: &str| {
            msg(parse_trajectory(
                &format!("t,x,y,z,roll,pitch,yaw\n0.1,0,0,0,0,0,0\n{body}"),
                p,
            ))
        };
        assert_eq!(
            bad("0.2,0,0,0,abc,0,0"),
            "ref/trajectories/world-002_p3.csv:3: column `roll`: `abc` is not a number"
        );
        assert_eq!(
            bad("0.2,0,0,0,0,0"),
            "ref/trajectories/world-002_p3.csv:3: 6 fields, but the header has 7"
        );
        assert_eq!(
            bad("0.1,0,0,0,0,0,0"),
            "ref/trajectories/world-002_p3.csv:3: column `t`: 0.1 does not come after 0.1"
        );
        assert_eq!(
            msg(parse_trajectory("t,x,y,z,roll,yaw\n", p)),
            "ref/trajectories/world-002_p3.csv:1: header has no column `pitch` (needs t, x, y, z, roll, pitch, yaw)"
        );
    }

    #[test]
    fn a_missing_folder_or_file_is_named() {
        let e = msg(read_reference(Path::new("/no/such/reference")));
        assert!(
            e.contains("/no/such/reference: no such reference folder"),
            "{e}"
        );
        assert_eq!(trajectory_file_name(2, 3), "world-002_p3.csv");
    }
}
