//! An assembly's bytes (what a worker exports, a checkpoint stores and a migration carries)
//! and its snapshots.
//!
//! Format `CDEMASM4`: the 8-byte header `CDEMASM4`; the spec as JSON (its tagged enums need a
//! self-describing format) after its length as a little-endian `u64`; the state (contact law,
//! reference, time step, committed and trial state) in postcard, whose wire format is
//! specified and writes every `f64` as its 8 little-endian bytes, so a state reads back bit
//! for bit; when the spec's `relaxation.predictor` is `extrapolated`, the last committed
//! step's increment in postcard (so the bytes of every other assembly are unchanged); and last
//! a CRC-32 (IEEE, little-endian) of every byte before it.
//!
//! The checksum is a CRC-32 (`crc32fast`) rather than a 64-bit hash: it is guaranteed to
//! catch every single-bit error and every burst of up to 32 bits (what a damaged disk block or
//! a bad copy does), it is the standard polynomial that any zlib can recompute, and it runs at
//! memory speed; an accidental match of a randomly damaged state (2^-32) is no concern for a
//! check against damage (it is not meant to stop tampering).
//!
//! The version is 4, not 3: `'3'` is one bit from the older `'2'` and `'1'`, so a flipped bit
//! in a new header could pass for an older format and draw the wrong error; `'4'` is two bits
//! from either.

use super::Assembly;
use super::extrapolate::StepIncrement;
use crate::error::{Error, Result};
use crate::homogenize::for_each_contact;
use crate::spec::Predictor;
use cosdem_common::micro::MicroSnapshot;
use serde::{Deserialize, Serialize};

/// The header of the format written (postcard and a CRC-32).
const MAGIC: &[u8; 8] = b"CDEMASM4";

/// The headers of the formats of earlier cosdems (bincode, no checksum): refused by name.
const OLD_MAGICS: [&[u8; 8]; 2] = [b"CDEMASM1", b"CDEMASM2"];

/// Bytes of the trailing CRC-32.
const CRC_LEN: usize = 4;

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
    /// Encodes spec, reference, committed and trial state (the format is described at the
    /// top of this module).
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
        let body = postcard::to_allocvec(&body).expect("encoding an assembly into memory");
        out.extend_from_slice(&body);
        if self.spec.relaxation.predictor == Predictor::Extrapolated {
            let step = postcard::to_allocvec(&self.last_step).expect("encoding into memory");
            out.extend_from_slice(&step);
        }
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        out
    }

    /// Restores an assembly encoded by [`Assembly::to_bytes`], bit for bit. Refuses, with the
    /// part at fault named, bytes of another format (the older bincode formats by name), a
    /// checksum that does not match (a flipped bit anywhere), and a spec or state that does
    /// not make an assembly.
    pub fn from_bytes(bytes: &[u8]) -> Result<Assembly> {
        let m = MAGIC.len();
        let head = &bytes[..m.min(bytes.len())];
        if let Some(old) = OLD_MAGICS.iter().find(|o| head == o.as_slice()) {
            return Err(Error::Decode(format!(
                "header: {} is the older bincode format of an earlier cosdem, which this cosdem \
                 no longer reads; the run must be restarted",
                String::from_utf8_lossy(&old[..])
            )));
        }
        if head != MAGIC {
            return Err(Error::Decode(format!(
                "header: no {} header (not a cosdem assembly state, or its header is damaged)",
                String::from_utf8_lossy(MAGIC)
            )));
        }
        if bytes.len() < m + 8 + CRC_LEN {
            return Err(Error::Decode(format!("{} bytes: too short for a state", bytes.len())));
        }
        let (covered, crc) = bytes.split_at(bytes.len() - CRC_LEN);
        let stored = u32::from_le_bytes(crc.try_into().expect("4 bytes"));
        let computed = crc32fast::hash(covered);
        if stored != computed {
            return Err(Error::Decode(format!(
                "checksum: CRC-32 {computed:08x} of the {} bytes does not match the stored \
                 {stored:08x} (the state was damaged)",
                covered.len()
            )));
        }
        let len = u64::from_le_bytes(covered[m..m + 8].try_into().expect("8 bytes")) as usize;
        let rest = &covered[m + 8..];
        if len > rest.len() {
            return Err(Error::Decode(format!(
                "spec: length {len} beyond the {} bytes left",
                rest.len()
            )));
        }
        let spec: crate::spec::AssemblySpec = serde_json::from_slice(&rest[..len])
            .map_err(|e| Error::Decode(format!("spec: {e}")))?;
        spec.validate()?;
        let (body, trailing): (Body, &[u8]) = postcard::take_from_bytes(&rest[len..])
            .map_err(|e| Error::Decode(format!("state body: {e}")))?;
        let (last_step, trailing) = if spec.relaxation.predictor == Predictor::Extrapolated {
            postcard::take_from_bytes::<Option<StepIncrement>>(trailing)
                .map_err(|e| Error::Decode(format!("last step: {e}")))?
        } else {
            (None, trailing)
        };
        if !trailing.is_empty() {
            return Err(Error::Decode(format!("state body: {} trailing bytes", trailing.len())));
        }
        if !(body.dt.is_finite() && body.dt > 0.0) {
            return Err(Error::Decode(format!(
                "dt: time step {} is not positive and finite",
                body.dt
            )));
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
        let step_ok = |s: &StepIncrement| [&s.dx, &s.dy, &s.dth].iter().all(|v| v.len() == n);
        if !sizes
            || !ok(&body.committed)
            || !body.trial.as_ref().is_none_or(ok)
            || !last_step.as_ref().is_none_or(step_ok)
        {
            return Err(Error::Decode("state body: inconsistent array sizes".into()));
        }
        Ok(Assembly {
            spec,
            law: body.law,
            refc: body.refc,
            dt: body.dt,
            committed: body.committed,
            trial: body.trial,
            last_step,
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

    /// Fluctuation field of a state, Eq. 35 ([`crate::fluctuation::fluctuation`]).
    pub fn fluctuation(&self, st: &super::State) -> Vec<[f64; 2]> {
        let d = &st.dynamics;
        let r = &self.refc;
        crate::fluctuation::fluctuation(&st.target.f, &r.x0, &r.y0, r.xc, &d.x, &d.y)
    }

    /// Best affine fit `x = c + G (X - X_c)` of the discs outside the boundary layer (all
    /// discs for a periodic boundary); returns `G`, the measured deformation gradient
    /// ([`crate::fluctuation::affine_fit`]).
    pub fn affine_fit(&self, st: &super::State) -> [[f64; 2]; 2] {
        let d = &st.dynamics;
        let r = &self.refc;
        crate::fluctuation::affine_fit(&r.x0, &r.y0, r.xc, &r.boundary, &d.x, &d.y)
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

#[cfg(test)]
mod tests {
    use super::*;
    use cosdem_common::MacroDeformation;

    /// A small relaxed assembly with a trial state on top of its committed one, so that both
    /// states, the contact histories and the spec are in the bytes.
    fn small() -> Assembly {
        let spec: crate::AssemblySpec = serde_json::from_value(serde_json::json!({
            "packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.04},
            "relaxation": {"max_steps": 2000}
        }))
        .unwrap();
        let mut a = Assembly::new(&spec).unwrap();
        let f = |e| MacroDeformation::from_gradient([[0.0, 0.0], [0.0, e]], 0.0, [0.0; 2]);
        a.solve(&f(-1e-3)).unwrap();
        a.commit();
        a.solve(&f(-2e-3)).unwrap();
        a
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// Encoded and decoded, an assembly is the same bit for bit: its re-encoding is the same
    /// bytes, and the evolving arrays hold the same f64 bit patterns (no tolerance: postcard
    /// writes each f64 as its 8 bytes).
    #[test]
    fn round_trip_is_bit_exact() {
        let a = small();
        let bytes = a.to_bytes();
        assert_eq!(&bytes[..8], MAGIC);
        let b = Assembly::from_bytes(&bytes).unwrap();
        assert_eq!(b.to_bytes(), bytes);
        for (s, t) in [(&a.committed, &b.committed), (a.trial().unwrap(), b.trial().unwrap())] {
            assert_eq!(bits(&s.dynamics.x), bits(&t.dynamics.x));
            assert_eq!(bits(&s.dynamics.th), bits(&t.dynamics.th));
            assert_eq!(bits(&s.pairs.fs), bits(&t.pairs.fs));
            assert_eq!(s, t);
        }
        assert_eq!(a.refc, b.refc);
        assert_eq!(a.dt.to_bits(), b.dt.to_bits());
    }

    /// Every single-bit flip of a small state, in the header, the spec length, the spec, the
    /// postcard body and the checksum itself, is refused, and the error names the part at
    /// fault: the header (a flip there makes no header of ours; never an older format's, so
    /// never the restart message), else the checksum. All bits are tried.
    #[test]
    fn every_flipped_bit_is_refused() {
        let bytes = small().to_bytes();
        assert!(bytes.len() < 64 * 1024, "a small state: {} bytes", bytes.len());
        let mut b = bytes.clone();
        for bit in 0..8 * bytes.len() {
            let (i, mask) = (bit / 8, 1u8 << (bit % 8));
            b[i] ^= mask;
            let e = Assembly::from_bytes(&b).map(|_| ()).unwrap_err().to_string();
            if i < MAGIC.len() {
                assert!(e.contains("header: no CDEMASM4 header"), "bit {bit}: {e}");
            } else {
                assert!(e.contains("checksum: CRC-32"), "bit {bit}: {e}");
            }
            b[i] ^= mask;
        }
        assert_eq!(b, bytes);
        assert!(Assembly::from_bytes(&b).is_ok());
    }

    /// The states of an earlier cosdem (bincode, headers `CDEMASM1` and `CDEMASM2`) are
    /// refused by name, with what to do.
    #[test]
    fn older_formats_are_refused_by_name() {
        for old in ["CDEMASM1", "CDEMASM2"] {
            let mut b = old.as_bytes().to_vec();
            b.extend_from_slice(&[0x2a; 64]);
            let e = Assembly::from_bytes(&b).map(|_| ()).unwrap_err().to_string();
            assert!(
                e.contains(old) && e.contains("older bincode format") && e.contains("restarted"),
                "{e}"
            );
        }
        let e = Assembly::from_bytes(b"CDEMASM4").map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("too short"), "{e}");
    }
}
