//! Sizes a spec implies before anything is built: the disc count of its packing (the hint a
//! master sends and a worker checks its limits against before building) and a bound on the
//! bytes of an exported assembly state.

use super::{AssemblySpec, BoundarySpec, Lattice, PackingSpec};
use crate::packing::hexagonal;

impl AssemblySpec {
    /// The number of discs [`crate::Assembly::new`] builds from this spec, computed from the
    /// packing's keys alone (nothing is allocated): exact for a hexagonal packing (the same
    /// row and column counts as the packing itself, penalty or periodic), for a random packing
    /// with a periodic boundary and for an explicit radius list with a periodic boundary; an
    /// upper bound for a random packing with a penalty boundary (the periodic specimen is cut
    /// to the square, which drops a few discs). Saturates at `u64::MAX` for absurd ratios of
    /// side to radius (and for non-finite keys), which every limit refuses.
    pub fn disc_count_hint(&self) -> u64 {
        let periodic = matches!(self.boundary, BoundarySpec::Periodic);
        let n = match &self.packing {
            PackingSpec::Hexagonal { radius, side, orientation, overlap } => {
                let lattice = Lattice { orientation: *orientation, overlap: *overlap };
                if !(radius.is_finite() && side.is_finite() && lattice.overlap.is_finite()) {
                    f64::NAN
                } else if periodic {
                    let (n_col, n_row) = hexagonal::periodic_grid(*radius, *side, lattice);
                    n_col as f64 * n_row as f64
                } else {
                    // Even rows hold `even` discs, odd rows `odd`.
                    let (n_row, even, odd) = hexagonal::square_rows(*radius, *side, lattice);
                    n_row.div_ceil(2) as f64 * even as f64 + (n_row / 2) as f64 * odd as f64
                }
            }
            PackingSpec::Random { r_min, r_max, radii, side, .. } => {
                if radii.is_empty() {
                    // `packing::random::loose`.
                    let er2 = (r_min * r_min + r_min * r_max + r_max * r_max) / 3.0;
                    (0.84 * side * side / (std::f64::consts::PI * er2)).round().max(4.0)
                } else {
                    radii.len() as f64
                }
            }
            PackingSpec::Explicit { radii, .. } => radii.len() as f64,
            PackingSpec::File { .. } => f64::NAN,
        };
        saturating_count(n)
    }
}

/// A count computed in `f64` as a `u64`: NaN and anything beyond `u64::MAX` saturate to
/// `u64::MAX` (a limit then refuses it), a negative count is 0.
fn saturating_count(n: f64) -> u64 {
    if n.is_nan() || n >= u64::MAX as f64 { u64::MAX } else { n.max(0.0) as u64 }
}

/// Bytes of one exported assembly state's protocol envelope beyond the model's bytes: the
/// Gauss point, the committed step, the disc count and the length prefixes of an
/// `AssemblyState` inside an `ExportStateReply` or `CommitReply` (each field at most a tag
/// and a 10-byte varint).
pub const STATE_ENVELOPE_BYTES: u64 = 64;

/// Fixed part of an encoded assembly: header, spec JSON (without an explicit radius list),
/// contact law, scalars, the last relaxed answer (stress and 6x6 tangent) and the checksum.
pub const STATE_FIXED_BYTES: u64 = 4096;

/// Bound on the bytes one disc adds to an encoded assembly (measured, with a margin, by
/// `state_bytes_bound_holds_for_real_assemblies` in `spec/tests.rs`): its reference data
/// (radius, inverse mass and inertia, rest position and rotation: 48 bytes, and its index in
/// the boundary layer), its committed dynamics (48 bytes), the Verlet list's build positions
/// (16 bytes), an explicit radius in the spec's JSON (at most 25 bytes), and its share of
/// the Verlet pairs (indices as varints, periodic offsets, tangential and rolling histories:
/// at most 42 bytes a pair; about 3 pairs a disc with the default skin, 9 with the largest
/// skin of a hexagonal packing), and with the extrapolated predictor its last step's
/// non-affine increment (24 bytes).
pub const STATE_BYTES_PER_DISC: u64 = 560;

/// An upper bound on the encoded size of one exported `AssemblyState` (protocol envelope
/// included) of an assembly of `discs` discs, with no trial state (what a commit exports,
/// what a checkpoint stores). A message carrying `k` such states needs at most `k` times
/// this: what the admission estimate compares with the message limit before a run starts.
pub fn state_bytes(discs: u64) -> u64 {
    STATE_ENVELOPE_BYTES
        .saturating_add(STATE_FIXED_BYTES)
        .saturating_add(discs.saturating_mul(STATE_BYTES_PER_DISC))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Assembly;
    use cosdem_common::MacroDeformation;

    /// The spec of `json` with a penalty (the default) or periodic boundary.
    fn spec(json: serde_json::Value, boundary: &str) -> AssemblySpec {
        let mut s: AssemblySpec = serde_json::from_value(json).unwrap();
        if boundary == "periodic" {
            s.boundary = BoundarySpec::Periodic;
        }
        s
    }

    fn random(boundary: &str, radii: Vec<f64>, skin: f64) -> AssemblySpec {
        spec(
            serde_json::json!({
                "packing": {"kind": "random", "r_min": 0.002, "r_max": 0.003, "radii": radii,
                            "side": 0.04, "seed": 3, "confining_stress": 1e5},
                "relaxation": {"skin": skin, "max_steps": 20000}
            }),
            boundary,
        )
    }

    fn hexagonal(radius: f64, side: f64, boundary: &str, skin: f64) -> AssemblySpec {
        spec(
            serde_json::json!({
                "packing": {"kind": "hexagonal", "radius": radius, "side": side},
                "relaxation": {"skin": skin, "max_steps": 20000}
            }),
            boundary,
        )
    }

    /// The hint is the count the packing builds: exactly, for hexagonal packings (penalty and
    /// periodic, sides that are and are not whole numbers of diameters), random packings with
    /// a periodic boundary and explicit radius lists; at least it, for a random packing cut to
    /// a penalty square.
    #[test]
    fn the_hint_is_the_disc_count_built() {
        let sides = [(0.005, 0.1), (0.005, 0.043), (0.0031, 0.0517), (0.001, 0.02)];
        for (r, l) in sides.into_iter().chain([(0.005, 0.0784f64.sqrt()), (0.005, 0.15)]) {
            for b in ["penalty", "periodic"] {
                for (orientation, overlap) in [("rows", 0.0), ("columns", 0.02)] {
                    let mut s = hexagonal(r, l, b, 0.5);
                    if let PackingSpec::Hexagonal { orientation: o, overlap: d, .. } =
                        &mut s.packing
                    {
                        *o = serde_json::from_value(serde_json::json!(orientation)).unwrap();
                        *d = overlap;
                    }
                    let built = Assembly::new(&s).unwrap().disc_count() as u64;
                    assert_eq!(
                        s.disc_count_hint(),
                        built,
                        "hexagonal r {r:?} side {l:?} {b} {orientation} {overlap}"
                    );
                }
            }
        }
        let s = random("periodic", vec![], 0.5);
        assert_eq!(s.disc_count_hint(), Assembly::new(&s).unwrap().disc_count() as u64);
        let radii: Vec<f64> = (0..40).map(|k| 0.002 + 0.00002 * k as f64).collect();
        let s = random("periodic", radii, 0.5);
        assert_eq!(s.disc_count_hint(), 40);
        assert_eq!(Assembly::new(&s).unwrap().disc_count(), 40);
        let s = random("penalty", vec![], 0.5);
        let built = Assembly::new(&s).unwrap().disc_count() as u64;
        assert!(built <= s.disc_count_hint() && built > 0, "{built} > {}", s.disc_count_hint());
    }

    /// Absurd keys saturate instead of wrapping: a limit refuses the hint.
    #[test]
    fn an_absurd_spec_saturates() {
        assert_eq!(hexagonal(1e-300, 1e300, "periodic", 0.5).disc_count_hint(), u64::MAX);
        let nan = AssemblySpec {
            packing: PackingSpec::hexagonal(f64::NAN, 0.1),
            ..AssemblySpec::default()
        };
        assert_eq!(nan.disc_count_hint(), u64::MAX);
        assert_eq!(state_bytes(u64::MAX), u64::MAX);
    }

    /// [`state_bytes`] bounds the encoded state (envelope included) of real assemblies after
    /// a committed deformation: hexagonal and random, penalty and periodic, the default and
    /// the largest Verlet skin, an explicit radius list (in the spec's JSON).
    #[test]
    fn state_bytes_bound_holds_for_real_assemblies() {
        let radii: Vec<f64> = (0..60).map(|k| 0.002 + 0.0000171 * k as f64).collect();
        let cases = [
            ("hexagonal penalty", hexagonal(0.002, 0.04, "penalty", 0.5)),
            ("hexagonal periodic skin 2", hexagonal(0.002, 0.04, "periodic", 2.0)),
            ("hexagonal penalty skin 2", hexagonal(0.002, 0.04, "penalty", 2.0)),
            ("random periodic", random("periodic", vec![], 0.5)),
            ("random periodic skin 2", random("periodic", vec![], 2.0)),
            ("random penalty skin 2", random("penalty", vec![], 2.0)),
            ("radii periodic skin 2", random("periodic", radii, 2.0)),
            ("random penalty skin 2, extrapolated", {
                let mut s = random("penalty", vec![], 2.0);
                s.relaxation.predictor = super::super::Predictor::Extrapolated;
                s
            }),
        ];
        let target = MacroDeformation::from_gradient([[-2e-3, 5e-4], [0.0, -1e-3]], 0.0, [0.0; 2]);
        for (name, s) in cases {
            let mut a = Assembly::new(&s).unwrap();
            let n = a.disc_count() as u64;
            let fresh = a.to_bytes().len() as u64;
            a.solve(&target).unwrap();
            a.commit();
            let bytes = a.to_bytes().len() as u64;
            let used = bytes.max(fresh) + STATE_ENVELOPE_BYTES;
            let per_disc = (bytes.max(fresh) - STATE_FIXED_BYTES.min(bytes)) as f64 / n as f64;
            eprintln!("{name}: {n} discs, {bytes} bytes ({fresh} as built), {per_disc:.0} / disc");
            assert!(used <= state_bytes(n), "{name}: {used} > {}", state_bytes(n));
        }
    }
}
