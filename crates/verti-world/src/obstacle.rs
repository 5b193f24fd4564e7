//! Obstacles: rocks (convex polytopes) and trees (upright cylinders), fixed to the ground.
//!
//! A rock is stored as the half-spaces `n·p <= d` that bound it in its local frame (origin at
//! its centre, z up, rotated by `yaw` about the vertical). Half-spaces make the two queries the
//! physics and the planner need cheap and exact enough: the penetration depth of a point inside
//! is `min(d - n·p)` and its contact normal the face that attains it. Vertices and the ground
//! footprint are derived once when the obstacle is built.

use verti_core::{Quat, Vec3};

/// A plane `normal · p = offset` with unit `normal`, bounding a rock in its local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Face {
    pub normal: Vec3,
    pub offset: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ObstacleShape {
    /// Convex polytope; `scale` is the Verti-Bench rock scale it was sized from (box
    /// 4.4s x 4.4s x 3.8s at full world scale).
    Rock { faces: Vec<Face>, scale: f64 },
    /// Vertical cylinder centred on the obstacle position.
    Tree { radius: f64, height: f64 },
}

/// A fixed obstacle with derived geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    shape: ObstacleShape,
    /// Centre of the shape in the world frame.
    position: Vec3,
    /// Rotation about the vertical axis (radians, counter-clockwise from +X).
    yaw: f64,
    rotation: Quat,
    /// World-frame vertices (rocks only).
    vertices: Vec<Vec3>,
    /// Ground footprint: convex polygon, counter-clockwise, world (x, y) (rocks only).
    footprint: Vec<[f64; 2]>,
    /// Horizontal radius of a circle around `position` containing the footprint.
    radius_xy: f64,
    z_min: f64,
    z_max: f64,
}

/// Most faces a rock may have. Generated rocks have 17 and imported boxes 6; finding the
/// vertices costs the cube of the face count times the face count, so a file with thousands
/// of faces per rock would hang the loader.
pub const MAX_ROCK_FACES: usize = 32;

impl Obstacle {
    /// Builds a rock. Fails when the faces do not bound a non-empty solid.
    pub fn rock(
        faces: Vec<Face>,
        scale: f64,
        position: Vec3,
        yaw: f64,
    ) -> Result<Obstacle, String> {
        if !(4..=MAX_ROCK_FACES).contains(&faces.len()) {
            return Err(format!(
                "a rock needs 4 to {MAX_ROCK_FACES} faces, got {}",
                faces.len()
            ));
        }
        for (i, f) in faces.iter().enumerate() {
            if !f.normal.is_finite()
                || !f.offset.is_finite()
                || (f.normal.norm() - 1.0).abs() > 1e-6
            {
                return Err(format!(
                    "face {i} must have a finite unit normal and offset"
                ));
            }
        }
        if !position.is_finite() || !yaw.is_finite() || !scale.is_finite() || scale <= 0.0 {
            return Err("position, yaw and scale must be finite (scale > 0)".into());
        }
        let local = polytope_vertices(&faces);
        if local.len() < 4 {
            return Err("the faces do not enclose a solid (fewer than 4 vertices)".into());
        }
        // finite faces can still meet at infinity (offsets near f64::MAX)
        if local.iter().any(|v| !v.is_finite()) {
            return Err("the faces meet at points too far away to represent".into());
        }
        let rotation = Quat::from_axis_angle(Vec3::Z, yaw);
        let vertices: Vec<Vec3> = local
            .iter()
            .map(|v| position + rotation.rotate(*v))
            .collect();
        let pts: Vec<[f64; 2]> = vertices.iter().map(|v| [v.x, v.y]).collect();
        let footprint = convex_hull_2d(&pts);
        let radius_xy = vertices
            .iter()
            .map(|v| (*v - position).norm_xy())
            .fold(0.0, f64::max);
        let z_min = vertices.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
        let z_max = vertices
            .iter()
            .map(|v| v.z)
            .fold(f64::NEG_INFINITY, f64::max);
        Ok(Obstacle {
            shape: ObstacleShape::Rock { faces, scale },
            position,
            yaw,
            rotation,
            vertices,
            footprint,
            radius_xy,
            z_min,
            z_max,
        })
    }

    /// Builds a tree (vertical cylinder centred at `position`).
    pub fn tree(radius: f64, height: f64, position: Vec3) -> Result<Obstacle, String> {
        if !(radius.is_finite() && radius > 0.0 && height.is_finite() && height > 0.0) {
            return Err(format!(
                "tree radius {radius} and height {height} must be positive"
            ));
        }
        if !position.is_finite() {
            return Err("tree position must be finite".into());
        }
        Ok(Obstacle {
            shape: ObstacleShape::Tree { radius, height },
            position,
            yaw: 0.0,
            rotation: Quat::IDENTITY,
            vertices: Vec::new(),
            footprint: Vec::new(),
            radius_xy: radius,
            z_min: position.z - 0.5 * height,
            z_max: position.z + 0.5 * height,
        })
    }

    pub fn shape(&self) -> &ObstacleShape {
        &self.shape
    }
    pub fn position(&self) -> Vec3 {
        self.position
    }
    pub fn yaw(&self) -> f64 {
        self.yaw
    }
    pub fn is_rock(&self) -> bool {
        matches!(self.shape, ObstacleShape::Rock { .. })
    }
    /// World-frame vertices of a rock (empty for trees).
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }
    /// Counter-clockwise footprint polygon of a rock (empty for trees: use `radius_xy`).
    pub fn footprint(&self) -> &[[f64; 2]] {
        &self.footprint
    }
    /// Radius of a vertical cylinder around the position that contains the obstacle.
    pub fn radius_xy(&self) -> f64 {
        self.radius_xy
    }
    pub fn z_range(&self) -> (f64, f64) {
        (self.z_min, self.z_max)
    }

    /// Signed horizontal distance from (x, y) to the footprint: negative inside.
    pub fn footprint_distance(&self, x: f64, y: f64) -> f64 {
        match &self.shape {
            ObstacleShape::Tree { radius, .. } => {
                ((x - self.position.x).powi(2) + (y - self.position.y).powi(2)).sqrt() - radius
            }
            ObstacleShape::Rock { .. } => polygon_signed_distance(&self.footprint, x, y),
        }
    }

    /// Signed distance from a world point to the obstacle surface (negative inside) and the
    /// outward unit normal of the nearest surface. Inside, the depth is exact; outside, the
    /// value for rocks is the largest face-plane distance (a lower bound of the true distance,
    /// exact in front of a face), which is what contact detection needs.
    pub fn signed_distance(&self, p: Vec3) -> (f64, Vec3) {
        let q = self.rotation.inverse_rotate(p - self.position);
        match &self.shape {
            ObstacleShape::Rock { faces, .. } => {
                let mut best = f64::NEG_INFINITY;
                let mut normal = Vec3::Z;
                for f in faces {
                    let s = f.normal.dot(q) - f.offset;
                    if s > best {
                        best = s;
                        normal = f.normal;
                    }
                }
                (best, self.rotation.rotate(normal))
            }
            ObstacleShape::Tree { radius, height } => {
                let r = (q.x * q.x + q.y * q.y).sqrt();
                let dr = r - radius;
                let dz = q.z.abs() - 0.5 * height;
                let radial = if r > 1e-12 {
                    Vec3::new(q.x / r, q.y / r, 0.0)
                } else {
                    Vec3::X
                };
                let vertical = Vec3::new(0.0, 0.0, q.z.signum());
                if dr > 0.0 && dz > 0.0 {
                    let d = (dr * dr + dz * dz).sqrt();
                    ((d), (radial * dr + vertical * dz) / d)
                } else if dr > dz {
                    (dr, radial)
                } else {
                    (dz, vertical)
                }
            }
        }
    }
}

/// Vertices of the polytope `{p : n_i·p <= d_i}` (all triple-plane intersections that satisfy
/// every constraint), deduplicated.
///
/// The tolerances are 1e-7 m (inside) and 1e-6 m (same vertex) for polytopes of a metre or
/// more, and shrink with the polytope below that: fixed tolerances merged every vertex of a
/// rock at scale 1e-8 into one, and generation panicked on the "rock" that was left.
pub fn polytope_vertices(faces: &[Face]) -> Vec<Vec3> {
    let size = faces.iter().map(|f| f.offset.abs()).fold(0.0, f64::max);
    let unit = size.min(1.0);
    let (inside_tol, same_tol) = (1e-7 * unit, 1e-6 * unit);
    let mut out: Vec<Vec3> = Vec::new();
    let n = faces.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (faces[i].normal, faces[j].normal, faces[k].normal);
                let det = a.dot(b.cross(c));
                if det.abs() < 1e-9 {
                    continue;
                }
                let p = (b.cross(c) * faces[i].offset
                    + c.cross(a) * faces[j].offset
                    + a.cross(b) * faces[k].offset)
                    / det;
                if faces
                    .iter()
                    .all(|f| f.normal.dot(p) <= f.offset + inside_tol)
                    && !out.iter().any(|q| (*q - p).norm() < same_tol)
                {
                    out.push(p);
                }
            }
        }
    }
    out
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, no repeated first point.
pub fn convex_hull_2d(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut pts: Vec<[f64; 2]> = points.to_vec();
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * pts.len());
    for &p in &pts {
        while hull.len() >= 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
            hull.pop();
        }
        hull.push(p);
    }
    let lower_len = hull.len() + 1;
    for &p in pts.iter().rev().skip(1) {
        while hull.len() >= lower_len && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
        {
            hull.pop();
        }
        hull.push(p);
    }
    hull.pop();
    hull
}

/// Signed distance from (x, y) to a counter-clockwise convex polygon (negative inside).
pub fn polygon_signed_distance(poly: &[[f64; 2]], x: f64, y: f64) -> f64 {
    let n = poly.len();
    let mut inside = n >= 3;
    let mut best = f64::INFINITY;
    for i in 0..n {
        let a = poly[i];
        let b = poly[(i + 1) % n];
        best = best.min(segment_distance(a, b, [x, y]));
        // Counter-clockwise polygon: a point right of any edge is outside.
        if (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]) < 0.0 {
            inside = false;
        }
    }
    if inside { -best } else { best }
}

/// Distance from point `p` to the segment from `a` to `b` (to `a` when the segment is a point).
pub fn segment_distance(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
    let (px, py) = (p[0] - a[0], p[1] - a[1]);
    let len2 = ex * ex + ey * ey;
    let t = if len2 > 0.0 {
        ((px * ex + py * ey) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (dx, dy) = (px - t * ex, py - t * ey);
    (dx * dx + dy * dy).sqrt()
}

/// The six faces of an axis-aligned box with the given full sizes, centred at the origin.
pub fn box_faces(size: Vec3) -> Vec<Face> {
    let h = size * 0.5;
    vec![
        Face {
            normal: Vec3::X,
            offset: h.x,
        },
        Face {
            normal: -Vec3::X,
            offset: h.x,
        },
        Face {
            normal: Vec3::Y,
            offset: h.y,
        },
        Face {
            normal: -Vec3::Y,
            offset: h.y,
        },
        Face {
            normal: Vec3::Z,
            offset: h.z,
        },
        Face {
            normal: -Vec3::Z,
            offset: h.z,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_rock_geometry() {
        let rock = Obstacle::rock(
            box_faces(Vec3::new(4.0, 2.0, 3.0)),
            1.0,
            Vec3::new(10.0, 5.0, 1.5),
            0.0,
        )
        .unwrap();
        assert_eq!(rock.vertices().len(), 8);
        assert_eq!(rock.footprint().len(), 4);
        assert_eq!(rock.z_range(), (0.0, 3.0));
        // inside: depth to the nearest face
        let (d, n) = rock.signed_distance(Vec3::new(11.8, 5.0, 1.5));
        assert!((d + 0.2).abs() < 1e-12 && (n - Vec3::X).norm() < 1e-12);
        // outside in front of a face: exact
        let (d, _) = rock.signed_distance(Vec3::new(10.0, 5.0, 3.5));
        assert!((d - 0.5).abs() < 1e-12);
        assert!((rock.footprint_distance(13.0, 5.0) - 1.0).abs() < 1e-12);
        assert!((rock.footprint_distance(10.0, 5.0) + 1.0).abs() < 1e-12);
    }

    #[test]
    fn rotated_rock_and_tree() {
        let rock = Obstacle::rock(
            box_faces(Vec3::new(4.0, 2.0, 2.0)),
            1.0,
            Vec3::ZERO,
            std::f64::consts::FRAC_PI_2,
        )
        .unwrap();
        // long axis now along y
        assert!(rock.footprint_distance(0.0, 1.9) < 0.0);
        assert!(rock.footprint_distance(1.9, 0.0) > 0.0);
        let tree = Obstacle::tree(0.5, 5.0, Vec3::new(0.0, 0.0, 2.5)).unwrap();
        let (d, n) = tree.signed_distance(Vec3::new(1.0, 0.0, 1.0));
        assert!((d - 0.5).abs() < 1e-12 && (n - Vec3::X).norm() < 1e-12);
        let (d, n) = tree.signed_distance(Vec3::new(0.0, 0.0, 5.2));
        assert!((d - 0.2).abs() < 1e-12 && (n - Vec3::Z).norm() < 1e-12);
        assert!(Obstacle::tree(-1.0, 5.0, Vec3::ZERO).is_err());
    }

    #[test]
    fn tiny_rocks_keep_their_vertices() {
        for size in [1e-3, 1e-8, 1e-20] {
            let rock = Obstacle::rock(
                box_faces(Vec3::new(4.0, 2.0, 3.0) * size),
                1.0,
                Vec3::ZERO,
                0.3,
            )
            .unwrap();
            assert_eq!(rock.vertices().len(), 8, "size {size}");
            assert_eq!(rock.footprint().len(), 4, "size {size}");
        }
    }

    #[test]
    fn open_faces_are_rejected() {
        let faces = box_faces(Vec3::new(1.0, 1.0, 1.0))[..3].to_vec();
        assert!(Obstacle::rock(faces, 1.0, Vec3::ZERO, 0.0).is_err());
    }
}
