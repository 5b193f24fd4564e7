//! Property tests of the task-range argument (`--tasks`, `tasks=`): any text is answered with a
//! selection or an error, never a panic, and selections round-trip through `format_tasks`.
//! Cases are capped so the whole file runs in about a second in a debug build.

use proptest::prelude::*;
use verti_bench::eval::{format_tasks, parse_tasks};

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 256,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// Text drawn from the characters a task range is made of, so the parser's branches are hit
/// far more often than by arbitrary Unicode. At most 8 characters: the largest range that can
/// be written, `1-999999`, still expands quickly.
fn range_like_text() -> impl Strategy<Value = String> {
    let alphabet: Vec<char> = "0123456789-, al+x\t".chars().collect();
    prop::collection::vec(prop::sample::select(alphabet), 0..=8)
        .prop_map(|chars| chars.into_iter().collect())
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        let _ = parse_tasks(&text);
    }

    #[test]
    fn range_like_text_never_panics_and_errors_quote_the_text(text in range_like_text()) {
        match parse_tasks(&text) {
            Ok(tasks) => {
                // what was accepted is a sorted set of task numbers from 1
                prop_assert!(tasks.windows(2).all(|w| w[0] < w[1]));
                prop_assert!(tasks.first().is_none_or(|&t| t >= 1));
            }
            Err(e) => prop_assert!(e.to_string().contains(&format!("`{text}`")), "{}", e),
        }
    }

    #[test]
    fn selections_round_trip_through_format_tasks(
        tasks in prop::collection::vec(1u32..=3000, 1..60),
    ) {
        let mut want = tasks.clone();
        want.sort_unstable();
        want.dedup();
        let text = format_tasks(&tasks);
        prop_assert_eq!(parse_tasks(&text).unwrap(), want.clone(), "{}", text);
        // and the text is canonical: formatting what was read gives the same text
        prop_assert_eq!(format_tasks(&want), text);
    }

    #[test]
    fn written_ranges_read_as_their_tasks(
        ranges in prop::collection::vec((1u32..=5000, 0u32..50), 1..8),
    ) {
        let text = ranges
            .iter()
            .map(|&(a, len)| if len == 0 { a.to_string() } else { format!("{a}-{}", a + len) })
            .collect::<Vec<_>>()
            .join(", ");
        let mut want: Vec<u32> = ranges.iter().flat_map(|&(a, len)| a..=a + len).collect();
        want.sort_unstable();
        want.dedup();
        prop_assert_eq!(parse_tasks(&text).unwrap(), want, "{}", text);
    }
}
