//! A director frame: the rotation Q = [d1 d2 d3] whose columns are the
//! directors, checked once when built so that every frame in a rod is a
//! rotation (the equations read d_i as an orthonormal, right-handed basis,
//! and a frame that is not one bends a rod that no load bends).

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

use super::ModelError;

/// A rotation matrix whose columns are the directors d1, d2, d3: orthonormal
/// and right-handed to [`Frame::TOLERANCE`]. Read it through
/// [`Frame::matrix`] (or as a `Matrix3` by dereference).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame(Matrix3<f64>);

impl Frame {
    /// The accepted orthonormality defect: max_ij |(QᵀQ − I)_ij| ≤ 1e-8.
    /// Problem files give the directors to nine digits (each a unit vector
    /// and d1·d3 = 0 to 1e-9, so |d2|² = |d3|²|d1|² − (d1·d3)² is 1 to about
    /// 4e-9); a frame twice as far from a rotation is a mistake, not
    /// rounding.
    pub const TOLERANCE: f64 = 1e-8;

    /// The frame of the columns of `q`, refused ([`ModelError::Frame`])
    /// unless max_ij |(QᵀQ − I)_ij| ≤ [`Frame::TOLERANCE`] and det Q > 0
    /// (right-handed; with orthonormal columns det Q = ±1 to about 3 ×
    /// the tolerance).
    pub fn new(q: Matrix3<f64>) -> Result<Frame, ModelError> {
        let determinant = q.determinant();
        let defect = if q.iter().all(|v| v.is_finite()) {
            (q.transpose() * q - Matrix3::identity()).amax()
        } else {
            f64::NAN
        };
        if defect <= Self::TOLERANCE && determinant > 0.0 {
            Ok(Frame(q))
        } else {
            Err(ModelError::Frame {
                defect,
                determinant,
            })
        }
    }

    /// The frame with directors d1, d3 and d2 = d3 × d1 (right-handed by
    /// construction; refused as in [`Frame::new`] when d1, d3 are not
    /// orthonormal).
    pub fn from_directors(d1: Vector3<f64>, d3: Vector3<f64>) -> Result<Frame, ModelError> {
        Frame::new(Matrix3::from_columns(&[d1, d3.cross(&d1), d3]))
    }

    /// The global frame d_i = e_i.
    pub fn identity() -> Frame {
        Frame(Matrix3::identity())
    }

    /// The rotation matrix [d1 d2 d3].
    pub fn matrix(&self) -> &Matrix3<f64> {
        &self.0
    }

    /// d_i, i = 0, 1, 2 (panics for i > 2, like a matrix column).
    pub fn director(&self, i: usize) -> Vector3<f64> {
        self.0.column(i).into_owned()
    }

    /// The frame turned by `angle` (rad) about its own director d_axis
    /// (axis 0, 1 or 2): R Q with R the rotation about d_axis. Refused
    /// ([`ModelError::Angle`]) for a non-finite angle. A product of
    /// rotations is a rotation up to a few rounding units, far inside the
    /// tolerance, so it is not checked again.
    pub fn turned(&self, axis: usize, angle: f64) -> Result<Frame, ModelError> {
        if !angle.is_finite() {
            return Err(ModelError::Angle(angle));
        }
        let a = Unit::new_normalize(self.director(axis));
        Ok(Frame(
            Rotation3::from_axis_angle(&a, angle).matrix() * self.0,
        ))
    }
}

impl Frame {
    /// The frame turned by `angle` (rad, any real number: a turn of 2π
    /// gives the same frame, but a continued angle runs through any number
    /// of turns) about the fixed direction `axis`: R(axis, angle) Q
    /// (Rodrigues). Refused ([`ModelError::Angle`]) for a non-finite angle
    /// or an axis that is not a finite non-zero vector.
    pub fn rotated(&self, axis: Vector3<f64>, angle: f64) -> Result<Frame, ModelError> {
        let norm = axis.norm();
        if !angle.is_finite() || !norm.is_finite() || norm == 0.0 {
            return Err(ModelError::Angle(angle));
        }
        let a = Unit::new_unchecked(axis / norm);
        Ok(Frame(
            Rotation3::from_axis_angle(&a, angle).matrix() * self.0,
        ))
    }
}

impl std::ops::Deref for Frame {
    type Target = Matrix3<f64>;

    /// A frame reads as its matrix (columns, transpose, products); it
    /// cannot be changed through it.
    fn deref(&self) -> &Matrix3<f64> {
        &self.0
    }
}

impl From<Frame> for Matrix3<f64> {
    fn from(f: Frame) -> Matrix3<f64> {
        f.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rotation_round_trips() {
        let q = *Rotation3::from_euler_angles(0.3, -1.1, 2.0).matrix();
        let f = Frame::new(q).unwrap();
        assert_eq!(*f.matrix(), q);
        assert_eq!(f.director(2), q.column(2).into_owned());
        let g = Frame::from_directors(Vector3::x(), Vector3::z()).unwrap();
        assert_eq!(g, Frame::identity());
        assert!((g.turned(1, 0.4).unwrap().director(1) - Vector3::y()).norm() < 1e-15);
        assert!(matches!(
            g.turned(1, f64::NAN),
            Err(ModelError::Angle(a)) if a.is_nan()
        ));
    }

    #[test]
    fn a_non_rotation_is_refused() {
        let stretched = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 1.0 + 1e-6));
        assert!(matches!(
            Frame::new(stretched),
            Err(ModelError::Frame { defect, .. }) if defect > Frame::TOLERANCE
        ));
        let mirrored = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
        assert!(matches!(
            Frame::new(mirrored),
            Err(ModelError::Frame { determinant, .. }) if determinant < 0.0
        ));
        let nan = Matrix3::from_element(f64::NAN);
        assert!(matches!(Frame::new(nan), Err(ModelError::Frame { .. })));
        // Directors at the problem file's tolerance are accepted.
        let d1 = Vector3::new(1.0 + 1e-9, 0.0, 0.0);
        let d3 = Vector3::new(1e-9, 0.0, 1.0 - 1e-9);
        assert!(Frame::from_directors(d1, d3).is_ok());
    }
}
