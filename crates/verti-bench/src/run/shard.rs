//! Splitting one evaluation over many machines.
//!
//! `--shard i/N` keeps every N-th task of a run's selection, starting at position `i`
//! (0-based, as Slurm array indices and Kubernetes completion indices are): shards are disjoint,
//! together they cover the selection, and consecutive tasks (which share a world, so cost about
//! the same) land on different shards, which balances their wall time. Each shard is an
//! ordinary run directory (resumable on its own); `super::merge` joins finished shards.

/// Shard `index` of `count` (0 ≤ index < count).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// Parses `i/N`, e.g. `0/4` … `3/4`.
    pub fn parse(s: &str) -> Result<Shard, String> {
        let bad = |why: &str| format!("bad shard `{s}`: {why} (use i/N with 0 <= i < N, e.g. 0/4)");
        let (i, n) = s.split_once('/').ok_or_else(|| bad("no `/`"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| bad(&format!("`{i}` is not a number")))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| bad(&format!("`{n}` is not a number")))?;
        if count == 0 {
            return Err(bad("N must be at least 1"));
        }
        if index >= count {
            return Err(bad(&format!("i must be below N ({count})")));
        }
        Ok(Shard { index, count })
    }

    /// The tasks of `all` (sorted task numbers) that belong to this shard.
    pub fn select(&self, all: &[u32]) -> Vec<u32> {
        all.iter()
            .enumerate()
            .filter(|(pos, _)| pos % self.count == self.index)
            .map(|(_, &n)| n)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_are_disjoint_and_cover_the_selection() {
        let all: Vec<u32> = (1..=103).collect();
        let mut seen = Vec::new();
        for i in 0..4 {
            let s = Shard::parse(&format!("{i}/4")).unwrap();
            let part = s.select(&all);
            // balanced to within one task
            assert!(part.len() == 25 || part.len() == 26, "{}", part.len());
            seen.extend(part);
        }
        seen.sort_unstable();
        assert_eq!(seen, all);
        assert_eq!(Shard::parse("0/1").unwrap().select(&all), all);
    }

    #[test]
    fn bad_shards_are_named() {
        for (s, why) in [
            ("4/4", "below N"),
            ("1/0", "at least 1"),
            ("a/3", "`a` is not a number"),
            ("3", "no `/`"),
        ] {
            let e = Shard::parse(s).unwrap_err();
            assert!(e.contains(why) && e.contains(s), "{s}: {e}");
        }
    }
}
