//! Minimal 3-D math in `f64`: vectors, rotation matrices and unit quaternions.
//!
//! The vehicle engine does millions of tiny operations per simulated second; plain `Copy`
//! structs with `#[inline]` methods keep that cheap and the code readable.

use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign, Div, Index, Mul, MulAssign, Neg, Sub, SubAssign};

/// A 3-vector. World frame convention everywhere in verti: X east, Y north, Z up (ISO).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Vec3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Vec3 {
    pub const ZERO: Vec3 = Vec3 {
        x: 0.0,
        y: 0.0,
        z: 0.0,
    };
    pub const X: Vec3 = Vec3 {
        x: 1.0,
        y: 0.0,
        z: 0.0,
    };
    pub const Y: Vec3 = Vec3 {
        x: 0.0,
        y: 1.0,
        z: 0.0,
    };
    pub const Z: Vec3 = Vec3 {
        x: 0.0,
        y: 0.0,
        z: 1.0,
    };

    #[inline]
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Vec3 { x, y, z }
    }
    #[inline]
    pub fn dot(self, o: Vec3) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline]
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    #[inline]
    pub fn norm_sq(self) -> f64 {
        self.dot(self)
    }
    #[inline]
    pub fn norm(self) -> f64 {
        self.norm_sq().sqrt()
    }
    /// Unit vector, or zero for a (near) zero vector.
    #[inline]
    pub fn normalized(self) -> Vec3 {
        let n = self.norm();
        if n > 1e-300 { self / n } else { Vec3::ZERO }
    }
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
    /// Horizontal (x, y) length.
    #[inline]
    pub fn norm_xy(self) -> f64 {
        (self.x * self.x + self.y * self.y).sqrt()
    }
    #[inline]
    pub fn scale_each(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }
    #[inline]
    pub fn to_array(self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    #[inline]
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl Sub for Vec3 {
    type Output = Vec3;
    #[inline]
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl Neg for Vec3 {
    type Output = Vec3;
    #[inline]
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}
impl Mul<f64> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn mul(self, s: f64) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl Mul<Vec3> for f64 {
    type Output = Vec3;
    #[inline]
    fn mul(self, v: Vec3) -> Vec3 {
        v * self
    }
}
impl Div<f64> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn div(self, s: f64) -> Vec3 {
        Vec3::new(self.x / s, self.y / s, self.z / s)
    }
}
impl AddAssign for Vec3 {
    #[inline]
    fn add_assign(&mut self, o: Vec3) {
        *self = *self + o;
    }
}
impl SubAssign for Vec3 {
    #[inline]
    fn sub_assign(&mut self, o: Vec3) {
        *self = *self - o;
    }
}
impl MulAssign<f64> for Vec3 {
    #[inline]
    fn mul_assign(&mut self, s: f64) {
        *self = *self * s;
    }
}
impl Index<usize> for Vec3 {
    type Output = f64;
    #[inline]
    fn index(&self, i: usize) -> &f64 {
        match i {
            0 => &self.x,
            1 => &self.y,
            2 => &self.z,
            _ => panic!("Vec3 index {i} out of range"),
        }
    }
}

/// A 3x3 matrix stored by rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mat3 {
    pub rows: [Vec3; 3],
}

impl Mat3 {
    pub const IDENTITY: Mat3 = Mat3 {
        rows: [Vec3::X, Vec3::Y, Vec3::Z],
    };
    #[inline]
    pub fn from_rows(a: Vec3, b: Vec3, c: Vec3) -> Mat3 {
        Mat3 { rows: [a, b, c] }
    }
    #[inline]
    pub fn from_cols(a: Vec3, b: Vec3, c: Vec3) -> Mat3 {
        Mat3::from_rows(
            Vec3::new(a.x, b.x, c.x),
            Vec3::new(a.y, b.y, c.y),
            Vec3::new(a.z, b.z, c.z),
        )
    }
    #[inline]
    pub fn diag(d: Vec3) -> Mat3 {
        Mat3::from_rows(
            Vec3::new(d.x, 0.0, 0.0),
            Vec3::new(0.0, d.y, 0.0),
            Vec3::new(0.0, 0.0, d.z),
        )
    }
    #[inline]
    pub fn col(&self, i: usize) -> Vec3 {
        Vec3::new(self.rows[0][i], self.rows[1][i], self.rows[2][i])
    }
    #[inline]
    pub fn transpose(&self) -> Mat3 {
        Mat3::from_cols(self.rows[0], self.rows[1], self.rows[2])
    }
    #[inline]
    pub fn mul_vec(&self, v: Vec3) -> Vec3 {
        Vec3::new(
            self.rows[0].dot(v),
            self.rows[1].dot(v),
            self.rows[2].dot(v),
        )
    }
    #[inline]
    pub fn mul_mat(&self, o: &Mat3) -> Mat3 {
        let t = o.transpose();
        Mat3::from_rows(
            Vec3::new(
                self.rows[0].dot(t.rows[0]),
                self.rows[0].dot(t.rows[1]),
                self.rows[0].dot(t.rows[2]),
            ),
            Vec3::new(
                self.rows[1].dot(t.rows[0]),
                self.rows[1].dot(t.rows[1]),
                self.rows[1].dot(t.rows[2]),
            ),
            Vec3::new(
                self.rows[2].dot(t.rows[0]),
                self.rows[2].dot(t.rows[1]),
                self.rows[2].dot(t.rows[2]),
            ),
        )
    }
}

/// A unit quaternion (w, x, y, z) representing a body-to-world rotation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quat {
    pub w: f64,
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Default for Quat {
    fn default() -> Self {
        Quat::IDENTITY
    }
}

impl Quat {
    pub const IDENTITY: Quat = Quat {
        w: 1.0,
        x: 0.0,
        y: 0.0,
        z: 0.0,
    };

    #[inline]
    pub fn from_axis_angle(axis: Vec3, angle: f64) -> Quat {
        let a = axis.normalized();
        let (s, c) = (0.5 * angle).sin_cos();
        Quat {
            w: c,
            x: a.x * s,
            y: a.y * s,
            z: a.z * s,
        }
    }

    /// Z-Y-X Tait–Bryan angles: R = Rz(yaw)·Ry(pitch)·Rx(roll) (Chrono's "Cardan XYZ").
    pub fn from_euler(roll: f64, pitch: f64, yaw: f64) -> Quat {
        let qz = Quat::from_axis_angle(Vec3::Z, yaw);
        let qy = Quat::from_axis_angle(Vec3::Y, pitch);
        let qx = Quat::from_axis_angle(Vec3::X, roll);
        qz.mul(qy).mul(qx)
    }

    /// (roll, pitch, yaw) of the Z-Y-X decomposition.
    pub fn to_euler(self) -> (f64, f64, f64) {
        let Quat { w, x, y, z } = self;
        let roll = (2.0 * (y * z + w * x)).atan2(w * w - x * x - y * y + z * z);
        let pitch = (2.0 * (w * y - x * z)).clamp(-1.0, 1.0).asin();
        let yaw = (2.0 * (x * y + w * z)).atan2(w * w + x * x - y * y - z * z);
        (roll, pitch, yaw)
    }

    #[inline]
    #[allow(clippy::should_implement_trait)]
    pub fn mul(self, o: Quat) -> Quat {
        Quat {
            w: self.w * o.w - self.x * o.x - self.y * o.y - self.z * o.z,
            x: self.w * o.x + self.x * o.w + self.y * o.z - self.z * o.y,
            y: self.w * o.y - self.x * o.z + self.y * o.w + self.z * o.x,
            z: self.w * o.z + self.x * o.y - self.y * o.x + self.z * o.w,
        }
    }

    #[inline]
    pub fn conjugate(self) -> Quat {
        Quat {
            w: self.w,
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }

    #[inline]
    pub fn normalized(self) -> Quat {
        let n = (self.w * self.w + self.x * self.x + self.y * self.y + self.z * self.z).sqrt();
        Quat {
            w: self.w / n,
            x: self.x / n,
            y: self.y / n,
            z: self.z / n,
        }
    }

    /// Rotates a body-frame vector into the world frame.
    #[inline]
    pub fn rotate(self, v: Vec3) -> Vec3 {
        let q = Vec3::new(self.x, self.y, self.z);
        let t = 2.0 * q.cross(v);
        v + self.w * t + q.cross(t)
    }

    /// Rotates a world-frame vector into the body frame.
    #[inline]
    pub fn inverse_rotate(self, v: Vec3) -> Vec3 {
        self.conjugate().rotate(v)
    }

    /// Rotation matrix (columns are the body axes in world coordinates).
    pub fn to_mat3(self) -> Mat3 {
        Mat3::from_cols(
            self.rotate(Vec3::X),
            self.rotate(Vec3::Y),
            self.rotate(Vec3::Z),
        )
    }

    /// Integrates an angular velocity given in the world frame over `dt` (exact for constant ω).
    pub fn integrate_world(self, omega: Vec3, dt: f64) -> Quat {
        let angle = omega.norm() * dt;
        if angle < 1e-12 {
            return self;
        }
        Quat::from_axis_angle(omega, angle).mul(self).normalized()
    }

    #[inline]
    pub fn is_finite(self) -> bool {
        self.w.is_finite() && self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}

/// Wraps an angle to [-π, π).
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    let t = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU);
    t - std::f64::consts::PI
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn euler_round_trip() {
        for &(r, p, y) in &[(0.1, -0.2, 0.3), (-1.0, 0.5, 3.0), (0.0, 0.0, -2.0)] {
            let q = Quat::from_euler(r, p, y);
            let (r2, p2, y2) = q.to_euler();
            assert!(
                close(r, r2) && close(p, p2) && close(y, y2),
                "{r2} {p2} {y2}"
            );
        }
    }

    #[test]
    fn rotation_matches_matrix_and_inverse() {
        let q = Quat::from_euler(0.3, 0.2, -1.1);
        let v = Vec3::new(1.0, -2.0, 0.5);
        let a = q.rotate(v);
        let b = q.to_mat3().mul_vec(v);
        assert!((a - b).norm() < 1e-12);
        assert!((q.inverse_rotate(a) - v).norm() < 1e-12);
        // yaw of +90° maps body X onto world Y
        let qy = Quat::from_euler(0.0, 0.0, std::f64::consts::FRAC_PI_2);
        assert!((qy.rotate(Vec3::X) - Vec3::Y).norm() < 1e-12);
    }

    #[test]
    fn integrate_constant_spin() {
        let mut q = Quat::IDENTITY;
        for _ in 0..1000 {
            q = q.integrate_world(Vec3::new(0.0, 0.0, 1.0), 1e-3);
        }
        let (_, _, yaw) = q.to_euler();
        assert!((yaw - 1.0).abs() < 1e-9);
    }

    #[test]
    fn wrap() {
        assert!(close(
            wrap_angle(3.0 * std::f64::consts::PI),
            -std::f64::consts::PI
        ));
        assert!(close(wrap_angle(0.5), 0.5));
        assert!(close(wrap_angle(-0.5 - std::f64::consts::TAU), -0.5));
    }
}
