use super::Assembly;
use crate::error::{Error, Result};
use crate::homogenize::for_each_contact;
use cosdem_common::micro::MicroSnapshot;
use serde::{Deserialize, Serialize};

const MAGIC: &[u8; 8] = b"CDEMASM2";

/// One active contact in a snapshot.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactForce {
    /// First disc.
    pub p: u32,
    /// Second disc.
    pub q: u32,
    /// Normal force (N, >= 0).
    pub fn_: f64,
    /// Tangential force (N) along `t = (-n_y, n_x)`, `n` from p to q.
    pub fs: f64,
}

/// What a visualization or the service needs of an assembly: the last trial state if there
/// is one, else the committed state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Centres x (m).
    pub x: Vec<f64>,
    /// Centres y (m).
    pub y: Vec<f64>,
    /// Radii (m).
    pub r: Vec<f64>,
    /// Rotations since the reference state (rad).
    pub th: Vec<f64>,
    /// Active contacts.
    pub contacts: Vec<ContactForce>,
    /// Fluctuation field, Eq. 35: `u_R = u - (Fbar - I)(X - X_c)` per disc.
    pub fluctuation: Vec<[f64; 2]>,
    /// Boundary-layer discs (penalty boundary).
    pub boundary: Vec<u32>,
}

/// The snapshot as the protocol carries it (flat arrays).
impl From<Snapshot> for MicroSnapshot {
    fn from(s: Snapshot) -> Self {
        Self {
            positions: s.x.iter().zip(&s.y).flat_map(|(x, y)| [*x, *y]).collect(),
            radii: s.r,
            rotations: s.th,
            contacts: s
                .contacts
                .iter()
                .flat_map(|c| [f64::from(c.p), f64::from(c.q), c.fn_, c.fs])
                .collect(),
            fluctuations: s.fluctuation.iter().flat_map(|u| [u[0], u[1]]).collect(),
        }
    }
}

/// The binary part of the encoding (everything but the spec).
#[derive(Serialize, Deserialize)]
struct Body {
    law: crate::contact::Law,
    refc: super::Reference,
    dt: f64,
    committed: super::State,
    trial: Option<super::State>,
}

impl Assembly {
    /// Encodes spec, reference, committed and trial state: the header `CDEMASM2`, the spec
    /// as length-prefixed JSON (its tagged enums need a self-describing format), then the
    /// state in bincode 2 (f64 as raw little-endian bit patterns: bit-exact).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        // Encoding plain data into memory cannot fail.
        let spec = serde_json::to_vec(&self.spec).expect("encoding a spec into memory");
        out.extend_from_slice(&(spec.len() as u64).to_le_bytes());
        out.extend_from_slice(&spec);
        let body = Body {
            law: self.law,
            refc: self.refc.clone(),
            dt: self.dt,
            committed: self.committed.clone(),
            trial: self.trial.clone(),
        };
        let body = bincode::serde::encode_to_vec(&body, bincode::config::standard())
            .expect("encoding an assembly into memory");
        out.extend_from_slice(&body);
        out
    }

    /// Restores an assembly encoded by [`Assembly::to_bytes`], bit for bit.
    pub fn from_bytes(bytes: &[u8]) -> Result<Assembly> {
        let m = MAGIC.len();
        if bytes.len() < m + 8 || &bytes[..m] != MAGIC {
            return Err(Error::Decode("missing CDEMASM2 header".into()));
        }
        let len = u64::from_le_bytes(bytes[m..m + 8].try_into().expect("8 bytes")) as usize;
        let rest = &bytes[m + 8..];
        if len > rest.len() {
            return Err(Error::Decode(format!(
                "spec length {len} beyond the {} bytes left",
                rest.len()
            )));
        }
        let spec: crate::spec::AssemblySpec =
            serde_json::from_slice(&rest[..len]).map_err(|e| Error::Decode(e.to_string()))?;
        spec.validate()?;
        let (body, used): (Body, usize) =
            bincode::serde::decode_from_slice(&rest[len..], bincode::config::standard())
                .map_err(|e| Error::Decode(e.to_string()))?;
        if len + used != rest.len() {
            return Err(Error::Decode(format!("{} trailing bytes", rest.len() - len - used)));
        }
        if !(body.dt.is_finite() && body.dt > 0.0) {
            return Err(Error::Decode(format!("time step {} is not positive and finite", body.dt)));
        }
        let n = body.refc.r.len();
        let ok = |st: &super::State| {
            let d = &st.dynamics;
            let p = &st.pairs;
            [&d.x, &d.y, &d.th, &d.vx, &d.vy, &d.w].iter().all(|v| v.len() == n)
                && p.i.iter().chain(&p.j).all(|&k| (k as usize) < n)
                && p.i.len() == p.fs.len()
                && p.j.len() == p.fs.len()
                && p.hr.len() == p.fs.len()
                && p.xb.len() == n
                && p.yb.len() == n
                && (p.ox.is_empty() || p.ox.len() == p.fs.len())
                && p.oy.len() == p.ox.len()
        };
        let refc = &body.refc;
        let sizes =
            [&refc.inv_m, &refc.inv_i, &refc.x0, &refc.y0, &refc.th0].iter().all(|v| v.len() == n)
                && refc.boundary.iter().all(|&k| (k as usize) < n);
        if !sizes || !ok(&body.committed) || !body.trial.as_ref().is_none_or(ok) {
            return Err(Error::Decode("inconsistent array sizes".into()));
        }
        Ok(Assembly {
            spec,
            law: body.law,
            refc: body.refc,
            dt: body.dt,
            committed: body.committed,
            trial: body.trial,
            work: Default::default(),
        })
    }

    /// Positions, radii, rotations, contact forces and fluctuation field.
    pub fn snapshot(&self) -> Snapshot {
        let st = self.trial.as_ref().unwrap_or(&self.committed);
        let d = &st.dynamics;
        let mut contacts = Vec::new();
        for_each_contact(&self.law, &d.x, &d.y, &self.refc.r, &st.pairs, |c| {
            contacts.push(ContactForce {
                p: st.pairs.i[c.k],
                q: st.pairs.j[c.k],
                fn_: c.fnorm,
                fs: c.fs,
            });
        });
        Snapshot {
            x: d.x.clone(),
            y: d.y.clone(),
            r: self.refc.r.clone(),
            th: d.th.clone(),
            contacts,
            fluctuation: self.fluctuation(st),
            boundary: self.refc.boundary.clone(),
        }
    }

    /// Fluctuation field of a state, Eq. 35.
    pub fn fluctuation(&self, st: &super::State) -> Vec<[f64; 2]> {
        let f = &st.target.f;
        let (x0, y0, xc) = (&self.refc.x0, &self.refc.y0, self.refc.xc);
        (0..self.disc_count())
            .map(|q| {
                let (dx, dy) = (x0[q] - xc[0], y0[q] - xc[1]);
                let ux = st.dynamics.x[q] - x0[q];
                let uy = st.dynamics.y[q] - y0[q];
                [
                    ux - ((f[0][0] - 1.0) * dx + f[0][1] * dy),
                    uy - (f[1][0] * dx + (f[1][1] - 1.0) * dy),
                ]
            })
            .collect()
    }

    /// Best affine fit `x = c + G (X - X_c)` of the discs outside the boundary layer (all
    /// discs for a periodic boundary); returns `G`, the measured deformation gradient.
    pub fn affine_fit(&self, st: &super::State) -> [[f64; 2]; 2] {
        let mut inb = vec![false; self.disc_count()];
        for &q in &self.refc.boundary {
            inb[q as usize] = true;
        }
        let (x0, y0, xc) = (&self.refc.x0, &self.refc.y0, self.refc.xc);
        let (mut n, mut mx, mut my, mut mxx, mut myy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for q in 0..self.disc_count() {
            if inb[q] {
                continue;
            }
            n += 1.0;
            mx += x0[q] - xc[0];
            my += y0[q] - xc[1];
            mxx += st.dynamics.x[q];
            myy += st.dynamics.y[q];
        }
        let (mx, my, mxx, myy) = (mx / n, my / n, mxx / n, myy / n);
        let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
        let mut rhs = [[0.0; 2]; 2];
        for q in 0..self.disc_count() {
            if inb[q] {
                continue;
            }
            let (px, py) = (x0[q] - xc[0] - mx, y0[q] - xc[1] - my);
            let (ux, uy) = (st.dynamics.x[q] - mxx, st.dynamics.y[q] - myy);
            a += px * px;
            b += px * py;
            c += py * py;
            rhs[0][0] += ux * px;
            rhs[0][1] += ux * py;
            rhs[1][0] += uy * px;
            rhs[1][1] += uy * py;
        }
        let inv = crate::boundary::mat_inv(&[[a, b], [b, c]]);
        crate::boundary::mat_mul(&rhs, &inv)
    }

    /// Boundary-average stress `(1/A) sum_q (x_q - X_c)_i f_q,j` over the penalty forces
    /// (`[xx, yy, xy, yx]`); None for a periodic boundary.
    pub fn boundary_stress(&self, st: &super::State) -> Option<[f64; 4]> {
        let p = self.penalty(&st.target)?;
        Some(p.boundary_stress(
            &st.dynamics.x,
            &st.dynamics.y,
            self.refc.xc,
            st.target.det() * self.refc.area,
        ))
    }
}

impl Assembly {
    /// Homogenization over an interior window: the contacts whose reference midpoint lies in
    /// the square of half-side `half` about `X_c`, divided by the current window area
    /// `det(Fbar) (2 half)^2`. With a penalty boundary this excludes the boundary layer and
    /// its contact deficit ("interior only" in THEORY.md). Coordination in the result counts
    /// all discs.
    pub fn window(&self, st: &super::State, half: f64) -> crate::homogenize::Homogenized {
        let d = &st.dynamics;
        let (x0, y0, xc) = (&self.refc.x0, &self.refc.y0, self.refc.xc);
        let pairs = &st.pairs;
        let area = st.target.det() * 4.0 * half * half;
        crate::homogenize::homogenize_subset(
            &self.law,
            &d.x,
            &d.y,
            &self.refc.r,
            pairs,
            area,
            |k| {
                let (i, j) = (pairs.i[k] as usize, pairs.j[k] as usize);
                let mx = 0.5 * (x0[i] + x0[j]) - xc[0];
                let my = 0.5 * (y0[i] + y0[j]) - xc[1];
                mx.abs() < half && my.abs() < half
            },
        )
    }
}
