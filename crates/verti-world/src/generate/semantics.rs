//! Cluster-based semantic assignment (paper §III-C, reference spec §3.5): a few cluster centres
//! are drawn on the 16x16 patch grid, every patch takes the class of its nearest centre (a
//! Voronoi partition in patch-index space), and every rigid patch draws its own friction.
//!
//! Unlike the reference, nothing is converted afterwards: the soil a patch is labelled with is
//! the soil that gets simulated there.

use crate::surface::{
    FRICTION_RANGE, PATCHES_PER_SIDE, Patch, RIGID_RESTITUTION, Surface, TerrainClass,
};
use crate::world::TerrainType;
use verti_core::Rng;

/// Mean and population standard deviation of the patch indices 0..15: where cluster centres
/// are drawn (reference: trunc(N(7.5, 4.6098))).
const CENTRE_MEAN: f64 = 7.5;
const CENTRE_STD: f64 = 4.6098;

/// Draws the classes of the clusters for a world of the given type.
pub fn cluster_classes(rng: &mut Rng, terrain_type: TerrainType) -> Vec<TerrainClass> {
    let (n_rigid, n_deformable) = match terrain_type {
        TerrainType::Rigid => (rng.int_inclusive(1, 7) as usize, 0),
        TerrainType::Deformable => (0, rng.int_inclusive(1, 3) as usize),
        TerrainType::Mixed => {
            let n = rng.int_inclusive(2, 10) as usize;
            let n_rigid = (rng.int_inclusive(1, n as i64 - 1) as usize).min(7);
            (n_rigid, (n - n_rigid).min(3))
        }
    };
    let mut classes: Vec<TerrainClass> = rng
        .sample_indices(TerrainClass::RIGID.len(), n_rigid)
        .into_iter()
        .map(|i| TerrainClass::RIGID[i])
        .collect();
    classes.extend(
        rng.sample_indices(TerrainClass::DEFORMABLE.len(), n_deformable)
            .into_iter()
            .map(|i| TerrainClass::DEFORMABLE[i]),
    );
    classes
}

/// Draws `k` distinct cluster centres (row, col) on the patch grid.
pub fn cluster_centres(rng: &mut Rng, k: usize) -> Vec<(usize, usize)> {
    let mut centres: Vec<(usize, usize)> = Vec::with_capacity(k);
    while centres.len() < k {
        let i = rng.gauss(CENTRE_MEAN, CENTRE_STD).trunc();
        let j = rng.gauss(CENTRE_MEAN, CENTRE_STD).trunc();
        let max = (PATCHES_PER_SIDE - 1) as f64;
        if (0.0..=max).contains(&i) && (0.0..=max).contains(&j) {
            let c = (i as usize, j as usize);
            if !centres.contains(&c) {
                centres.push(c);
            }
        }
    }
    centres
}

/// Samples the physical surface of one patch of a class.
pub fn sample_surface(rng: &mut Rng, class: TerrainClass) -> Surface {
    match (class.friction_distribution(), class.soil()) {
        (Some((mean, std)), _) => Surface::Rigid {
            friction: rng
                .gauss(mean, std)
                .clamp(FRICTION_RANGE.0, FRICTION_RANGE.1),
            restitution: RIGID_RESTITUTION,
        },
        (None, Some(soil)) => Surface::Deformable { soil },
        (None, None) => unreachable!("every class is rigid or deformable"),
    }
}

/// The 256 patches of a world of the given type, row-major.
pub fn generate_patches(rng: &mut Rng, terrain_type: TerrainType) -> Vec<Patch> {
    let classes = cluster_classes(rng, terrain_type);
    let centres = cluster_centres(rng, classes.len());
    let mut patches = Vec::with_capacity(PATCHES_PER_SIDE * PATCHES_PER_SIDE);
    for i in 0..PATCHES_PER_SIDE {
        for j in 0..PATCHES_PER_SIDE {
            // nearest centre; ties go to the first centre drawn
            let mut best = 0;
            let mut best_d = usize::MAX;
            for (k, &(ci, cj)) in centres.iter().enumerate() {
                let d = (i.abs_diff(ci)).pow(2) + (j.abs_diff(cj)).pow(2);
                if d < best_d {
                    best_d = d;
                    best = k;
                }
            }
            let class = classes[best];
            patches.push(Patch {
                class,
                surface: sample_surface(rng, class),
            });
        }
    }
    patches
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn types_get_the_right_kinds_of_class() {
        for seed in 0..50 {
            let mut rng = Rng::new(seed);
            let rigid = generate_patches(&mut rng, TerrainType::Rigid);
            assert!(rigid.iter().all(|p| !p.class.is_deformable()));
            let soil = generate_patches(&mut rng, TerrainType::Deformable);
            assert!(
                soil.iter()
                    .all(|p| p.class.is_deformable() && p.surface.is_deformable())
            );
            let classes = cluster_classes(&mut rng, TerrainType::Mixed);
            assert!(
                classes.iter().any(|c| c.is_deformable())
                    && classes.iter().any(|c| !c.is_deformable())
            );
            assert!((2..=10).contains(&classes.len()));
        }
    }

    #[test]
    fn frictions_are_clipped_normals_per_class() {
        let mut rng = Rng::new(3);
        let mut sum = 0.0;
        let n = 20000;
        for _ in 0..n {
            match sample_surface(&mut rng, TerrainClass::Grass) {
                Surface::Rigid {
                    friction,
                    restitution,
                } => {
                    assert!((0.1..=1.0).contains(&friction));
                    assert_eq!(restitution, 0.01);
                    sum += friction;
                }
                _ => panic!("grass is rigid"),
            }
        }
        assert!((sum / n as f64 - 0.36).abs() < 0.005);
    }

    #[test]
    fn voronoi_regions_are_contiguous_to_their_centre() {
        // every patch is at least as close to its own centre as to any other
        let mut rng = Rng::new(9);
        let classes = cluster_classes(&mut rng, TerrainType::Rigid);
        let centres = cluster_centres(&mut rng, classes.len());
        assert_eq!(centres.len(), classes.len());
        let mut dedup = centres.clone();
        dedup.sort();
        dedup.dedup();
        assert_eq!(dedup.len(), centres.len());
    }
}
