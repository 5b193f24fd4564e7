//! Elevation heuristic (paper §IV-A): split the elevation map in front of the vehicle into five
//! regions and steer toward the one whose mean elevation is most like the ground under the
//! vehicle and whose variance is lowest; blend that direction with the path direction.
//!
//! Geometry (done right, unlike the reference's mirrored blocks, spec §6.2): a heading-aligned
//! elevation crop 12.8 m (scaled) wide; the current patch is its central 2.6 m square; the five
//! regions are the bands of the area 2.6–6.4 m ahead, left to right, each 2.6 m wide. Regions
//! are ranked by (|mean − mean under the vehicle|, variance) lexicographically, as in the
//! reference, after rounding the mean difference to 5 cm so that variance decides among
//! regions of practically equal height.

use crate::pid::{Pid, PidParams};
use verti_bench::{Action, CropSpec, MobilitySystem, Observation, TaskInfo};

#[derive(Clone, Debug, PartialEq)]
pub struct EhParams {
    pub pid: PidParams,
    /// Weight of the terrain direction (the path direction gets 1 − weight).
    pub terrain_weight: f64,
}

impl Default for EhParams {
    fn default() -> Self {
        EhParams {
            pid: PidParams::default(),
            terrain_weight: 0.2,
        }
    }
}

pub struct ElevationHeuristic {
    params: EhParams,
    pid: Pid,
    scale: f64,
}

const CROP_CELLS: usize = 65;
const CROP_RES: f64 = 0.2;
const BAND: usize = 13;

impl ElevationHeuristic {
    pub fn new(params: EhParams) -> Self {
        let pid = Pid::new(params.pid.clone());
        ElevationHeuristic {
            params,
            pid,
            scale: 1.0,
        }
    }

    /// Index (0 = leftmost) of the chosen region and its heading error.
    pub fn choose_region(&self, obs: &Observation) -> (usize, f64) {
        let spec = CropSpec {
            size: CROP_CELLS,
            resolution: CROP_RES * self.scale,
        };
        let crop = obs.elevation_crop(spec);
        let mean_var = |rows: std::ops::Range<usize>, cols: std::ops::Range<usize>| {
            let vals: Vec<f64> = rows
                .flat_map(|r| cols.clone().map(move |c| (r, c)))
                .map(|(r, c)| crop.get(r, c))
                .collect();
            let m = vals.iter().sum::<f64>() / vals.len() as f64;
            let v = vals.iter().map(|x| (x - m).powi(2)).sum::<f64>() / vals.len() as f64;
            (m, v)
        };
        let centre = CROP_CELLS / 2;
        let (under, _) = mean_var(
            centre - BAND / 2..centre + BAND / 2 + 1,
            centre - BAND / 2..centre + BAND / 2 + 1,
        );
        let mut best = (f64::INFINITY, f64::INFINITY, 0usize);
        for k in 0..5 {
            let (m, v) = mean_var(0..2 * BAND, k * BAND..(k + 1) * BAND);
            let dm = ((m - under).abs() / (0.05 * self.scale)).round();
            if (dm, v) < (best.0, best.1) {
                best = (dm, v, k);
            }
        }
        let k = best.2;
        // centre of the band: ahead = (centre - BAND) cells, left = (centre - band centre) cells
        let ahead = (centre - BAND) as f64 * spec.resolution;
        let left = (centre as f64 - (k * BAND + BAND / 2) as f64) * spec.resolution;
        (k, left.atan2(ahead))
    }
}

impl MobilitySystem for ElevationHeuristic {
    fn name(&self) -> &str {
        "eh"
    }
    fn control_rate(&self) -> f64 {
        self.params.pid.rate
    }
    fn reset(&mut self, task: &TaskInfo) {
        self.pid.reset(task);
        self.scale = task.world_scale;
    }
    fn act(&mut self, obs: &Observation) -> Action {
        let e_path = self.pid.path_heading_error(obs);
        let (_, e_terrain) = self.choose_region(obs);
        let w = self.params.terrain_weight;
        let e = w * e_terrain + (1.0 - w) * e_path;
        Action::HighLevel {
            speed: self.pid.target_speed(),
            steering: self.pid.steer(e),
        }
    }
}
