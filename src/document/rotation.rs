//! Rotations as the compiler computes them: quaternions to matrices, products, a vector
//! turned by a quaternion, and the Jacobi eigen-decomposition that gives a body's principal
//! axes (the split tier's `geom_masses.rs` and `volumes.rs`, the URDF reader's inertials).
//!
//! In the document tier, the lowest, so that each tier above may use it; it uses nothing
//! of the crate.

/// MuJoCo's `mjEPS`.
pub(crate) const EPS: f64 = 1e-14;
/// The eigen-decomposition's tolerance between eigenvalues it orders.
const EIG_EPS: f64 = 1e-12;
/// The largest off-diagonal element the eigen-decomposition leaves, relative to the
/// diagonal's size.
const OFF_DIAGONAL: f64 = 1e-15;

pub(crate) fn quat_to_mat(q: &[f64; 4]) -> [f64; 9] {
    let (q0, q1, q2, q3) = (q[0], q[1], q[2], q[3]);
    let (q00, q01, q02, q03) = (q0 * q0, q0 * q1, q0 * q2, q0 * q3);
    let (q11, q12, q13) = (q1 * q1, q1 * q2, q1 * q3);
    let (q22, q23, q33) = (q2 * q2, q2 * q3, q3 * q3);
    [
        q00 + q11 - q22 - q33,
        2.0 * (q12 - q03),
        2.0 * (q13 + q02),
        2.0 * (q12 + q03),
        q00 - q11 + q22 - q33,
        2.0 * (q23 - q01),
        2.0 * (q13 - q02),
        2.0 * (q23 + q01),
        q00 - q11 - q22 + q33,
    ]
}

pub(crate) fn mul_quat(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

pub(crate) fn normalized(mut q: [f64; 4]) -> [f64; 4] {
    let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if norm < EPS {
        return [1.0, 0.0, 0.0, 0.0];
    }
    for x in &mut q {
        *x /= norm;
    }
    q
}

/// `v` rotated by `q` (unchanged for the zero vector and the unit quaternion).
pub(crate) fn rotate(v: &[f64; 3], q: &[f64; 4]) -> [f64; 3] {
    if v == &[0.0; 3] {
        return [0.0; 3];
    }
    if q == &[1.0, 0.0, 0.0, 0.0] {
        return *v;
    }
    // t = w v + q x v, then v + 2 q x t.
    let t = [
        q[0] * v[0] + q[2] * v[2] - q[3] * v[1],
        q[0] * v[1] + q[3] * v[0] - q[1] * v[2],
        q[0] * v[2] + q[1] * v[1] - q[2] * v[0],
    ];
    [
        v[0] + 2.0 * (q[2] * t[2] - q[3] * t[1]),
        v[1] + 2.0 * (q[3] * t[0] - q[1] * t[2]),
        v[2] + 2.0 * (q[1] * t[1] - q[2] * t[0]),
    ]
}

pub(crate) fn mat_mul(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    let mut out = [0.0; 9];
    for r in 0..3 {
        for c in 0..3 {
            out[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
        }
    }
    out
}

pub(crate) fn transpose(a: &[f64; 9]) -> [f64; 9] {
    [a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8]]
}

/// The rotation of Euler angles (radians) in MJCF's extrinsic `XYZ` sequence (URDF's
/// `rpy`): each turn about a fixed axis of the parent, pre-multiplied (`mjuu_mulquat`,
/// whose normalization leaves a product within mjEPS of unit length alone), as MuJoCo
/// resolves an `euler` orientation.
pub(crate) fn euler_xyz(angles: [f64; 3]) -> [f64; 4] {
    let mut q = [1.0, 0.0, 0.0, 0.0];
    for (i, a) in angles.into_iter().enumerate() {
        let mut rot = [(a / 2.0).cos(), 0.0, 0.0, 0.0];
        rot[i + 1] = (a / 2.0).sin();
        q = normvec(mul_quat(&rot, &q));
    }
    q
}

/// MuJoCo's `mjuu_normvec` on a quaternion: divided by its norm unless that is within
/// mjEPS of 1 (or below mjEPS).
pub(crate) fn normvec(mut q: [f64; 4]) -> [f64; 4] {
    let n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if n2 < EPS {
        return q;
    }
    let n = n2.sqrt();
    if (n - 1.0).abs() > EPS {
        for x in &mut q {
            *x /= n;
        }
    }
    q
}

/// `r m r'` (MuJoCo's `mjuu_mulRMRT`), all 3-by-3, row-major.
pub(crate) fn rotate_matrix(r: &[f64; 9], m: &[f64; 9]) -> [f64; 9] {
    mat_mul(&mat_mul(r, m), &transpose(r))
}

/// The minimal rotation from `[0, 0, 1]` to `v` (MuJoCo's `mjuu_z2quat`): about
/// `z x v`, by the angle `atan2(|z x v|, v_z)`; about x when `v` is (anti)parallel to z.
pub(crate) fn z_to_quat(v: &[f64; 3]) -> [f64; 4] {
    // z x v, normalized as mjuu_normvec does: left alone when tiny or within mjEPS of
    // unit length.
    let mut axis = [-v[1], v[0], 0.0];
    let norm2 = axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2];
    let s = if norm2 < EPS {
        0.0
    } else {
        let n = norm2.sqrt();
        if (n - 1.0).abs() > EPS {
            for x in &mut axis {
                *x /= n;
            }
        }
        n
    };
    if s < 1e-10 {
        axis = [1.0, 0.0, 0.0];
    }
    let ang = s.atan2(v[2]);
    let half_sin = (ang / 2.0).sin();
    [
        (ang / 2.0).cos(),
        axis[0] * half_sin,
        axis[1] * half_sin,
        axis[2] * half_sin,
    ]
}

/// The eigenvalues (decreasing) and principal axes (as a quaternion) of the symmetric
/// matrix `m`: Jacobi rotations accumulated in a quaternion, as the compiler computes a
/// body's principal axes.
pub(crate) fn eigen(m: &[f64; 9]) -> ([f64; 3], [f64; 4]) {
    let mut quat = [1.0, 0.0, 0.0, 0.0];
    let mut values = [m[0], m[4], m[8]];
    for _ in 0..500 {
        let axes = quat_to_mat(&quat);
        let d = mat_mul(&mat_mul(&transpose(&axes), m), &axes);
        values = [d[0], d[4], d[8]];
        // The largest off-diagonal element: (row, column, rotation axis).
        let (r, c, k) = if d[1].abs() > d[2].abs() && d[1].abs() > d[5].abs() {
            (0, 1, 2)
        } else if d[2].abs() > d[5].abs() {
            (0, 2, 1)
        } else {
            (1, 2, 0)
        };
        let scale = d[0].abs() + d[4].abs() + d[8].abs();
        if d[3 * r + c].abs() < EIG_EPS.min(OFF_DIAGONAL * scale) {
            break;
        }
        let tau = (d[4 * c] - d[4 * r]) / (2.0 * d[3 * r + c]);
        let t = if tau >= 0.0 {
            1.0 / (tau + (1.0 + tau * tau).sqrt())
        } else {
            -1.0 / (-tau + (1.0 + tau * tau).sqrt())
        };
        // The half angle from the angle itself: precise for the small rotations that
        // finish the job (from the cosine, they round to none).
        let half = 0.5 * t.abs().atan();
        if half.sin() == 0.0 {
            break;
        }
        let mut rot = [half.cos(), 0.0, 0.0, 0.0];
        rot[k + 1] = if tau >= 0.0 { -half.sin() } else { half.sin() };
        if k == 1 {
            rot[k + 1] = -rot[k + 1];
        }
        quat = normalized(mul_quat(&quat, &normalized(rot)));
    }
    // Decreasing order: swap neighbours (0-1, 1-2, 0-1), turning the axes with them.
    for j in 0..3 {
        let lead = j % 2;
        if values[lead] + EIG_EPS < values[lead + 1] {
            values.swap(lead, lead + 1);
            // The compiler's rounded cos(pi/4), not FRAC_1_SQRT_2: the same turn, the same bits.
            #[allow(clippy::approx_constant)]
            let mut rot = [0.707106781186548, 0.0, 0.0, 0.0];
            rot[(lead + 2) % 3 + 1] = rot[0];
            quat = normalized(mul_quat(&quat, &rot));
        }
    }
    (values, quat)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn principal_axes_of_a_diagonal_inertia_are_sorted() {
        let (values, quat) = eigen(&[1.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 2.0]);
        assert_eq!(values, [3.0, 2.0, 1.0]);
        // The axes turn with the values: the first principal axis is the old y.
        let m = quat_to_mat(&quat);
        assert!((m[3].abs() - 1.0).abs() < 1e-12, "{m:?}");
    }
}
