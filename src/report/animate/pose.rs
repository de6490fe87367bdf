//! A body's pose in a row of the solution: the columns it is read from, its position and
//! attitude (angle, quaternion or Cardan angles), and poses between rows.

use super::*;

/// Where each body's pose is in the solution's columns.
pub(super) enum Attitude {
    Planar(Option<usize>),
    Quaternion([usize; 4]),
    Cardan([usize; 3]),
    Fixed,
}

pub(super) struct PoseColumns {
    pub(super) position: [Option<usize>; 3],
    pub(super) attitude: Attitude,
}

/// A rigid pose: centre `r` and rotation `rot` (body → world).
#[derive(Clone, Copy)]
pub(super) struct Pose {
    pub(super) r: [f64; 3],
    pub(super) rot: [[f64; 3]; 3],
}

impl Pose {
    pub(super) const GROUND: Pose = Pose {
        r: [0.0; 3],
        rot: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    pub(super) fn apply(&self, p: &[f64]) -> [f64; 3] {
        let p3 = to3(p);
        let mut w = self.r;
        for (i, wi) in w.iter_mut().enumerate() {
            *wi += (0..3).map(|j| self.rot[i][j] * p3[j]).sum::<f64>();
        }
        w
    }

    /// A direction given in body coordinates, in the world.
    pub(super) fn direction(&self, d: &[f64]) -> [f64; 3] {
        let o = Pose {
            r: [0.0; 3],
            rot: self.rot,
        };
        o.apply(d)
    }
}

/// A planar or spatial point as three coordinates (z = 0 in the plane).
pub(super) fn to3(p: &[f64]) -> [f64; 3] {
    [
        p.first().copied().unwrap_or(0.0),
        p.get(1).copied().unwrap_or(0.0),
        p.get(2).copied().unwrap_or(0.0),
    ]
}

pub(super) fn is_point_mass(b: &Body) -> bool {
    match b.inertia {
        Inertia::Planar(j) => j == 0.0,
        Inertia::Principal(j) => j.iter().all(|&v| v == 0.0),
    }
}

pub(super) fn pose_columns(
    scene: &Scene,
    sol: &Solution,
    source: &str,
) -> Result<Vec<PoseColumns>> {
    let col = |name: String| sol.columns.iter().position(|c| *c == name);
    let need = |b: &str, c: &'static str| {
        col(format!("{b}.{c}")).ok_or_else(|| ReportError::MissingColumn {
            origin: source.to_string(),
            body: b.to_string(),
            column: c,
        })
    };
    let spatial = scene.dimension == Dimension::Spatial;
    scene
        .bodies
        .iter()
        .map(|b| {
            let n = &b.name;
            let position = [
                Some(need(n, "x")?),
                Some(need(n, "y")?),
                if spatial { Some(need(n, "z")?) } else { None },
            ];
            let attitude = if !spatial {
                let angle = col(format!("{n}.angle"));
                if angle.is_none() && !b.points.is_empty() {
                    need(n, "angle")?;
                }
                Attitude::Planar(angle)
            } else if let (Some(w), Some(x), Some(y), Some(z)) = (
                col(format!("{n}.qw")),
                col(format!("{n}.qx")),
                col(format!("{n}.qy")),
                col(format!("{n}.qz")),
            ) {
                Attitude::Quaternion([w, x, y, z])
            } else if let (Some(a), Some(t), Some(f)) = (
                col(format!("{n}.psi")),
                col(format!("{n}.theta")),
                col(format!("{n}.phi")),
            ) {
                Attitude::Cardan([a, t, f])
            } else if is_point_mass(b) {
                Attitude::Fixed
            } else {
                return Err(ReportError::MissingAttitude {
                    origin: source.to_string(),
                    body: n.clone(),
                });
            };
            Ok(PoseColumns { position, attitude })
        })
        .collect()
}

pub(super) fn pose(cols: &PoseColumns, row: &[f64]) -> Pose {
    let v = |i: Option<usize>| i.map_or(0.0, |i| row[i]);
    let r = cols.position.map(v);
    let rot = match cols.attitude {
        Attitude::Planar(a) => {
            let (s, c) = v(a).sin_cos();
            [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
        }
        Attitude::Quaternion(q) => {
            let [mut w, mut x, mut y, mut z] = q.map(|i| row[i]);
            let n = (w * w + x * x + y * y + z * z).sqrt();
            if n > 0.0 {
                (w, x, y, z) = (w / n, x / n, y / n, z / n);
            }
            [
                [
                    1.0 - 2.0 * (y * y + z * z),
                    2.0 * (x * y - w * z),
                    2.0 * (x * z + w * y),
                ],
                [
                    2.0 * (x * y + w * z),
                    1.0 - 2.0 * (x * x + z * z),
                    2.0 * (y * z - w * x),
                ],
                [
                    2.0 * (x * z - w * y),
                    2.0 * (y * z + w * x),
                    1.0 - 2.0 * (x * x + y * y),
                ],
            ]
        }
        Attitude::Cardan([a, t, f]) => {
            // seed 16.2: R = Rz(ψ) Ry(θ) Rx(φ)
            let (s1, c1) = row[a].sin_cos();
            let (s2, c2) = row[t].sin_cos();
            let (s3, c3) = row[f].sin_cos();
            [
                [c1 * c2, c1 * s2 * s3 - s1 * c3, c1 * s2 * c3 + s1 * s3],
                [s1 * c2, s1 * s2 * s3 + c1 * c3, s1 * s2 * c3 - c1 * s3],
                [-s2, c2 * s3, c2 * c3],
            ]
        }
        Attitude::Fixed => Pose::GROUND.rot,
    };
    Pose { r, rot }
}

/// The angle (rad) of the rotation from `a` to `b`.
pub(super) fn turn_angle(a: &Pose, b: &Pose) -> f64 {
    // tr(Aᵀ B) = 1 + 2 cos θ; the sine form keeps small angles accurate
    let m = |i: usize, j: usize| (0..3).map(|l| a.rot[l][i] * b.rot[l][j]).sum::<f64>();
    let trace = m(0, 0) + m(1, 1) + m(2, 2);
    let s = [m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1)];
    let sin = 0.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    sin.atan2(0.5 * (trace - 1.0))
}

/// The planar angle of each body over the frames, unwrapped (continuous).
pub(super) fn planar_angles(poses: &[Vec<Pose>]) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = Vec::with_capacity(poses.len());
    for (k, frame) in poses.iter().enumerate() {
        let row = frame
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let a = p.rot[1][0].atan2(p.rot[0][0]);
                match k {
                    0 => a,
                    _ => {
                        let prev = out[k - 1][i];
                        let tau = std::f64::consts::TAU;
                        a + tau * ((prev - a) / tau).round()
                    }
                }
            })
            .collect();
        out.push(row);
    }
    out
}

/// The pose a fraction `a` of the way from `p` to `q`: the centre along the straight line,
/// the attitude along the shortest rotation (planar: the angle, linearly).
pub(super) fn interpolate_pose(p: &Pose, q: &Pose, a: f64) -> Pose {
    use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
    let r = std::array::from_fn(|i| p.r[i] + a * (q.r[i] - p.r[i]));
    let m = |x: &Pose| Matrix3::from_fn(|i, j| x.rot[i][j]);
    let qp = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m(p)));
    let qq = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m(q)));
    let qs = qp.try_slerp(&qq, a, 1e-12).unwrap_or(qp);
    let rm = qs.to_rotation_matrix();
    Pose {
        r,
        rot: std::array::from_fn(|i| std::array::from_fn(|j| rm[(i, j)])),
    }
}

pub(super) fn quaternion(p: &Pose) -> [f64; 4] {
    use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
    let m = Matrix3::from_fn(|i, j| p.rot[i][j]);
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
    [q.w, q.i, q.j, q.k]
}
