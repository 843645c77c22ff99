use super::Assembly;
use crate::error::{Error, Result};
use crate::homogenize::for_each_contact;
use serde::{Deserialize, Serialize};

const MAGIC: &[u8; 8] = b"CDEMASM1";

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

impl Assembly {
    /// Encodes spec, reference, committed and trial state (bincode 2, f64 bit patterns).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        // Encoding plain data into a Vec cannot fail.
        let body = bincode::serde::encode_to_vec(self, bincode::config::standard())
            .expect("encoding an assembly into memory");
        out.extend_from_slice(&body);
        out
    }

    /// Restores an assembly encoded by [`Assembly::to_bytes`], bit for bit.
    pub fn from_bytes(bytes: &[u8]) -> Result<Assembly> {
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(Error::Decode("missing CDEMASM1 header".into()));
        }
        let (a, used): (Assembly, usize) =
            bincode::serde::decode_from_slice(&bytes[MAGIC.len()..], bincode::config::standard())
                .map_err(|e| Error::Decode(e.to_string()))?;
        if used + MAGIC.len() != bytes.len() {
            return Err(Error::Decode(format!(
                "{} trailing bytes",
                bytes.len() - used - MAGIC.len()
            )));
        }
        a.spec.validate()?;
        Ok(a)
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
