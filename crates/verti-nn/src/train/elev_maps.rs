//! Verti-Bench's 1000 elevation maps (`verti-bench-data/elev_maps/N.bmp`, 128 x 128 grey, the
//! SWAE's training data), read from `../shared` at training time and never copied.

use crate::train::swae::BatchSource;
use std::path::Path;
use verti_core::Rng;

/// Maps as height fractions (grey / 255), each side x side, row 0 = top of the image.
#[derive(Clone, Debug)]
pub struct MapSet {
    pub side: usize,
    pub maps: Vec<Vec<f32>>,
    /// File names, in the order of `maps`.
    pub names: Vec<String>,
}

/// Reads every `*.bmp` of `dir` (sorted by file number), checking each is side x side grey.
pub fn load_dir(dir: &Path) -> Result<MapSet, String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut files: Vec<(u64, std::path::PathBuf)> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("bmp")))
        .map(|p| {
            let n = p
                .file_stem()
                .and_then(|s| s.to_str())
                .and_then(|s| s.parse().ok())
                .unwrap_or(u64::MAX);
            (n, p)
        })
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(format!("{}: no .bmp elevation maps found", dir.display()));
    }
    let mut set = MapSet {
        side: 0,
        maps: Vec::with_capacity(files.len()),
        names: Vec::with_capacity(files.len()),
    };
    for (_, path) in files {
        let img = image::open(&path)
            .map_err(|e| format!("{}: cannot read the map: {e}", path.display()))?
            .into_luma8();
        let (w, h) = img.dimensions();
        if w != h || (set.side != 0 && w as usize != set.side) {
            return Err(format!(
                "{}: map is {w} x {h}, expected square maps of one size ({} x {})",
                path.display(),
                set.side,
                set.side
            ));
        }
        set.side = w as usize;
        set.maps.push(
            img.into_raw()
                .into_iter()
                .map(|g| f32::from(g) / 255.0)
                .collect(),
        );
        set.names.push(
            path.file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into(),
        );
    }
    Ok(set)
}

impl MapSet {
    /// Splits off a seeded random `fraction` of the maps for validation: (train, validation).
    pub fn split(self, fraction: f64, seed: u64) -> (MapSet, MapSet) {
        let mut order: Vec<usize> = (0..self.maps.len()).collect();
        let mut rng = Rng::derive(seed, "map-split", 0);
        for i in (1..order.len()).rev() {
            let j = (rng.next_u64() % (i as u64 + 1)) as usize;
            order.swap(i, j);
        }
        let n_val = ((self.maps.len() as f64 * fraction).round() as usize).min(self.maps.len());
        let pick = |idx: &[usize]| MapSet {
            side: self.side,
            maps: idx.iter().map(|&i| self.maps[i].clone()).collect(),
            names: idx.iter().map(|&i| self.names[i].clone()).collect(),
        };
        let mut val_idx = order[..n_val].to_vec();
        let mut train_idx = order[n_val..].to_vec();
        val_idx.sort();
        train_idx.sort();
        (pick(&train_idx), pick(&val_idx))
    }

    /// Mean and standard deviation of every pixel of every map.
    pub fn moments(&self) -> (f64, f64) {
        let n = (self.maps.len() * self.side * self.side) as f64;
        let mean = self
            .maps
            .iter()
            .flatten()
            .map(|&v| f64::from(v))
            .sum::<f64>()
            / n;
        let var = self
            .maps
            .iter()
            .flatten()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / n;
        (mean, var.sqrt())
    }

    /// All maps standardised with (mean, std), flattened one after another.
    pub fn standardised(&self, mean: f64, std: f64) -> Vec<f32> {
        self.maps
            .iter()
            .flatten()
            .map(|&v| ((f64::from(v) - mean) / std) as f32)
            .collect()
    }
}

/// Training batches: random maps under one of the 8 rotations/mirrors of the square (terrain
/// has no preferred orientation), standardised.
pub struct AugmentedMaps {
    pub set: MapSet,
    pub mean: f64,
    pub std: f64,
}

/// Index of the source pixel of (r, c) under dihedral transform `t` (0..8) of an n x n grid.
pub fn dihedral(t: u8, n: usize, r: usize, c: usize) -> usize {
    let (r, c) = if t & 4 != 0 { (c, r) } else { (r, c) };
    let r = if t & 1 != 0 { n - 1 - r } else { r };
    let c = if t & 2 != 0 { n - 1 - c } else { c };
    r * n + c
}

impl BatchSource for AugmentedMaps {
    fn sample(&mut self, rng: &mut Rng, batch: usize) -> Vec<f32> {
        let n = self.set.side;
        let mut out = Vec::with_capacity(batch * n * n);
        for _ in 0..batch {
            let map = &self.set.maps[(rng.next_u64() % self.set.maps.len() as u64) as usize];
            let t = (rng.next_u64() % 8) as u8;
            for r in 0..n {
                for c in 0..n {
                    let v = f64::from(map[dihedral(t, n, r, c)]);
                    out.push(((v - self.mean) / self.std) as f32);
                }
            }
        }
        out
    }
}
