//! Choosing which reference tasks to compare (`--tasks`).

use crate::error::{CompareError, Result};
use crate::reference::RefOutcome;

/// The reference tasks a filter selects, as indices into `tasks`, in file order, each once.
///
/// The filter is `all` or a comma-separated list of:
/// * `W:P`: world index W, pair P (e.g. `2:0`);
/// * `W:*` (or `W:`): every pair of world W;
/// * `N` or `N-M`: the N-th (to M-th) task of the outcomes file, counting from 1.
///
/// An item that selects nothing is an error naming it.
pub fn select_tasks(tasks: &[RefOutcome], filter: &str) -> Result<Vec<usize>> {
    let filter = filter.trim();
    if filter.is_empty() || filter == "all" {
        return Ok((0..tasks.len()).collect());
    }
    let mut chosen = vec![false; tasks.len()];
    for item in filter.split(',').map(str::trim) {
        let bad = |why: String| CompareError::Argument(format!("--tasks item `{item}`: {why}"));
        let number = |s: &str, what: &str| -> Result<u32> {
            s.trim()
                .parse()
                .map_err(|_| bad(format!("`{s}` is not a {what}")))
        };
        let hits: Vec<usize> = if let Some((w, p)) = item.split_once(':') {
            let w = number(w, "world index")?;
            let p = match p.trim() {
                "" | "*" => None,
                p => Some(number(p, "pair number")?),
            };
            (0..tasks.len())
                .filter(|&i| tasks[i].world_index == w && p.is_none_or(|p| tasks[i].pair == p))
                .collect()
        } else {
            let (a, b) = match item.split_once('-') {
                Some((a, b)) => (number(a, "task number")?, number(b, "task number")?),
                None => {
                    let n = number(item, "task number")?;
                    (n, n)
                }
            };
            if a == 0 || a > b {
                return Err(bad("task numbers count from 1, ranges go upwards".into()));
            }
            (a as usize - 1..b as usize)
                .filter(|&i| i < tasks.len())
                .collect()
        };
        if hits.is_empty() {
            return Err(bad(format!(
                "selects no task of the reference ({} tasks)",
                tasks.len()
            )));
        }
        for i in hits {
            chosen[i] = true;
        }
    }
    Ok((0..tasks.len()).filter(|&i| chosen[i]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::parse_outcomes;
    use std::path::Path;

    fn tasks() -> Vec<RefOutcome> {
        let line = |w: u32, p: u32| {
            format!(
                r#"{{"world": "vb/config{w}_low", "world_index": {w}, "pair": {p}, "outcome": "stuck", "time": 10, "mean_abs_roll": 1, "max_abs_roll": 2, "mean_abs_pitch": 1, "max_abs_pitch": 2}}"#
            )
        };
        let text: Vec<String> = [(1, 0), (1, 1), (9, 0), (9, 4), (17, 2)]
            .iter()
            .map(|&(w, p)| line(w, p))
            .collect();
        parse_outcomes(&text.join("\n"), Path::new("o.jsonl")).unwrap()
    }

    #[test]
    fn filters_by_world_pair_and_position() {
        let t = tasks();
        assert_eq!(select_tasks(&t, "all").unwrap(), vec![0, 1, 2, 3, 4]);
        assert_eq!(select_tasks(&t, "9:4, 1:0").unwrap(), vec![0, 3]);
        assert_eq!(select_tasks(&t, "9:*").unwrap(), vec![2, 3]);
        assert_eq!(select_tasks(&t, "1:").unwrap(), vec![0, 1]);
        assert_eq!(select_tasks(&t, "2-3,5,3").unwrap(), vec![1, 2, 4]);
        assert_eq!(select_tasks(&t, "4-99").unwrap(), vec![3, 4]);
        let err = |f: &str| select_tasks(&t, f).unwrap_err().to_string();
        assert_eq!(
            err("9:7"),
            "--tasks item `9:7`: selects no task of the reference (5 tasks)"
        );
        assert_eq!(err("x:1"), "--tasks item `x:1`: `x` is not a world index");
        assert!(err("0").contains("count from 1"));
        assert!(err("3-2").contains("ranges go upwards"));
        assert!(err("6").contains("selects no task"));
    }
}
