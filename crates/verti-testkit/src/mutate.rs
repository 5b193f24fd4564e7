//! Seeded mutations of byte strings: bytes flipped, inserted, deleted, the string cut short,
//! and numbers of a text swapped for extreme ones.
//!
//! An [`Edit`] is drawn by proptest and applied to a real file by [`apply`]. Its positions are
//! any `usize`, taken modulo the current length when applied, so every edit applies to every
//! string (however earlier edits changed its length) and proptest can shrink a failing case
//! freely. The strategies here are the common mixes; a target that wants another mix (more
//! flips, more numbers, its own insert bytes) weights these in a `prop_oneof!` of its own.

use proptest::prelude::*;

/// One edit of a byte string; positions are taken modulo the current length.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Edit {
    /// XOR the byte at this position with a mask (a no-op on an empty string).
    Flip(usize, u8),
    /// Insert these bytes before this position (the end included).
    Insert(usize, Vec<u8>),
    /// Delete up to this many bytes from this position.
    Delete(usize, usize),
    /// Cut the string at this position (the end included: possibly no cut).
    Truncate(usize),
    /// Replace the n-th number in the text (of [`number_spans`]) by an extreme one.
    Number(usize, &'static str),
}

/// Extreme numbers for [`Edit::Number`]: values at the edges of `f64` and YAML's special
/// floats (which a reader must refuse or carry without overflow), sizes at an edge (0, 1, 2),
/// and integers whose products overflow `usize` or `u32` (2^31, 2^32, 2^62, 2^63, 2^64 - 1),
/// since a size read from a file that sizes an allocation must be bounded first.
pub const EXTREMES: &[&str] = &[
    // edges of f64 and YAML's special floats
    "1e30",
    "-1e30",
    "1e308",
    "-0.0",
    "0",
    "-1",
    ".nan",
    ".inf",
    "1e-320",
    "4294967296",
    "99999999999999999999",
    "0.5",
    // sizes at an edge, and sizes whose products overflow
    "1",
    "2",
    "65536",
    "4294967297",
    "2147483648",
    "4611686018427387904",
    "9223372036854775808",
    "18446744073709551615",
];

/// Flips of a byte by a nonzero mask, so that the byte always changes.
pub fn flip_edit() -> impl Strategy<Value = Edit> {
    (any::<usize>(), 1u8..=255).prop_map(|(p, x)| Edit::Flip(p, x))
}

/// Swaps of a number of the text for one of `extremes`.
pub fn number_edit(extremes: &'static [&'static str]) -> impl Strategy<Value = Edit> {
    (any::<usize>(), prop::sample::select(extremes)).prop_map(|(n, v)| Edit::Number(n, v))
}

/// Edits of a binary file, any byte values, each kind as likely: flips, inserts of up to 15
/// bytes, deletions of up to 63, cuts. No number swaps (see [`number_edit`] to add them).
pub fn edit_strategy() -> impl Strategy<Value = Edit> {
    prop_oneof![
        flip_edit(),
        (any::<usize>(), prop::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(p, b)| Edit::Insert(p, b)),
        (any::<usize>(), 1usize..64).prop_map(|(p, n)| Edit::Delete(p, n)),
        any::<usize>().prop_map(Edit::Truncate),
    ]
}

/// [`text_edit_strategy_with`] the default [`EXTREMES`].
pub fn text_edit_strategy() -> impl Strategy<Value = Edit> {
    text_edit_strategy_with(EXTREMES)
}

/// Edits of YAML text that keep it ASCII, so most cases get past the UTF-8 check into the
/// parser and the validation: flips below 128, inserts of YAML's syntax characters, deletions,
/// cuts, and swaps of a number for one of `extremes`. Swaps are half of all edits, since a file
/// that still parses reaches the most checks.
pub fn text_edit_strategy_with(extremes: &'static [&'static str]) -> impl Strategy<Value = Edit> {
    let yaml_bytes = prop::sample::select(b"[]{},:-#&*!|>'\" 0123456789.eE+abc\n\t".to_vec());
    prop_oneof![
        1 => (any::<usize>(), 1u8..=127).prop_map(|(p, x)| Edit::Flip(p, x)),
        1 => (any::<usize>(), prop::collection::vec(yaml_bytes, 1..16))
            .prop_map(|(p, b)| Edit::Insert(p, b)),
        1 => (any::<usize>(), 1usize..64).prop_map(|(p, n)| Edit::Delete(p, n)),
        1 => any::<usize>().prop_map(Edit::Truncate),
        4 => number_edit(extremes),
    ]
}

/// Start and end of every number-looking token: a digit or `-` after a space, `[`, `,` or
/// `:`, and the digits, `.`, `e`, `-` and `+` that follow. This finds YAML's numbers (and a few
/// non-numbers, which is harmless) without a parser, so it also works on damaged text.
pub fn number_spans(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = (b[i].is_ascii_digit() || b[i] == b'-')
            && i > 0
            && matches!(b[i - 1], b' ' | b'[' | b',' | b':');
        if starts {
            let j = i + b[i..]
                .iter()
                .take_while(|c| c.is_ascii_digit() || matches!(c, b'.' | b'e' | b'-' | b'+'))
                .count();
            out.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// Applies `edit` to `bytes` in place; every edit applies to every string, the empty one
/// included (a flip of nothing and a swap in a text without numbers change nothing).
pub fn apply(bytes: &mut Vec<u8>, edit: &Edit) {
    let at = |p: usize, len: usize| if len == 0 { 0 } else { p % len };
    match edit {
        Edit::Flip(p, x) => {
            if !bytes.is_empty() {
                let i = at(*p, bytes.len());
                bytes[i] ^= x;
            }
        }
        Edit::Insert(p, b) => {
            let i = at(*p, bytes.len() + 1);
            bytes.splice(i..i, b.iter().copied());
        }
        Edit::Delete(p, n) => {
            let i = at(*p, bytes.len());
            let j = i.saturating_add(*n).min(bytes.len());
            bytes.drain(i..j);
        }
        Edit::Truncate(p) => bytes.truncate(at(*p, bytes.len() + 1)),
        Edit::Number(n, v) => {
            let spans = number_spans(bytes);
            if !spans.is_empty() {
                let (i, j) = spans[n % spans.len()];
                bytes.splice(i..j, v.bytes());
            }
        }
    }
}

/// A copy of `bytes` with `edits` applied in order.
pub fn edited(bytes: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    for e in edits {
        apply(&mut b, e);
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spans_of(text: &str) -> Vec<&str> {
        number_spans(text.as_bytes())
            .into_iter()
            .map(|(i, j)| &text[i..j])
            .collect()
    }

    #[test]
    fn number_spans_find_yaml_numbers_after_a_separator() {
        assert_eq!(
            spans_of("a: 1.5\nb: [-2, 3e+4,5]\nc:7"),
            ["1.5", "-2", "3e+4", "5", "7"]
        );
        // not after a separator: a name's digits, the very start
        assert!(spans_of("x1: a2\n9").is_empty());
        assert!(spans_of("42 and more").is_empty());
        assert!(spans_of("").is_empty());
    }

    #[test]
    fn apply_takes_positions_modulo_the_length() {
        let e = |edit: Edit| edited(b"abcdef", &[edit]);
        assert_eq!(e(Edit::Flip(7, 0x20)), b"aBcdef");
        assert_eq!(e(Edit::Insert(7, b"XY".to_vec())), b"XYabcdef");
        assert_eq!(e(Edit::Insert(6, b"Z".to_vec())), b"abcdefZ");
        assert_eq!(e(Edit::Delete(4, 10)), b"abcd");
        assert_eq!(e(Edit::Delete(1, usize::MAX)), b"a");
        assert_eq!(e(Edit::Truncate(10)), b"abc");
        assert_eq!(e(Edit::Truncate(6)), b"abcdef");
    }

    #[test]
    fn apply_swaps_the_nth_number_for_an_extreme_one() {
        let text = b"a: 1, b: [2.5, -3]";
        assert_eq!(
            edited(text, &[Edit::Number(1, ".nan")]),
            b"a: 1, b: [.nan, -3]"
        );
        assert_eq!(
            edited(text, &[Edit::Number(5, "1e308")]),
            b"a: 1, b: [2.5, 1e308]"
        );
        assert_eq!(
            edited(b"no numbers", &[Edit::Number(0, "1")]),
            b"no numbers"
        );
    }

    #[test]
    fn every_edit_applies_to_the_empty_string() {
        for edit in [
            Edit::Flip(3, 1),
            Edit::Delete(3, 2),
            Edit::Truncate(3),
            Edit::Number(3, "0"),
        ] {
            assert!(edited(b"", &[edit]).is_empty());
        }
        assert_eq!(edited(b"", &[Edit::Insert(5, b"x".to_vec())]), b"x");
    }
}
