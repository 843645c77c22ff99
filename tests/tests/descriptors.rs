//! The micro descriptors (porosity, coordination, fabric, sliding, mean rotation) reach the
//! master intact: the same assemblies solved through the pool of in-process DEM workers over
//! a real HTTP/2 gRPC transport (`in_process_duplex`: encoding, framing, decoding) and through
//! the direct in-thread path give the same bits, descriptors included, for every Gauss point
//! and every step; and the quick example job, run through the run driver, shows every Gauss
//! point's descriptors to the step observer. Determinism is the contract, so the comparisons
//! are exact.

mod common;

use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_common::{GaussPointId, MacroDeformation, MicroDescriptors, MicroResponse};
use cosdem_dem::AssemblySpec;
use cosdem_fem::material::{Material, MaterialInput, TrialId};
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_pool::{DirectDem, Pool, PoolConfig};

/// A small random penalty assembly (~50 discs at 100 kPa) with friction: contacts slide under
/// the shear below, so every descriptor is away from its trivial value.
fn spec() -> AssemblySpec {
    serde_json::from_str(
        r#"{"packing": {"kind": "random", "r_min": 0.002, "r_max": 0.004, "side": 0.04,
            "seed": 5, "confining_stress": 100000.0},
            "boundary": {"kind": "penalty", "eps_f": 6.7e6, "eps_c": 1000.0}}"#,
    )
    .unwrap()
}

fn ids() -> Vec<GaussPointId> {
    (0..3).map(|p| GaussPointId::new(0, p)).collect()
}

/// Gauss point `p` at load `lam`: compression in y, some shear, a micro-rotation.
fn inputs(lam: f64) -> Vec<MaterialInput> {
    ids()
        .into_iter()
        .enumerate()
        .map(|(p, id)| {
            let s = lam * (1.0 + p as f64);
            let g = [[0.3 * s, 0.5 * s], [0.0, -s]];
            MaterialInput {
                gauss_point: id,
                deformation: MacroDeformation::from_gradient(g, 0.2 * s, [0.0; 2]),
            }
        })
        .collect()
}

fn bits(d: &MicroDescriptors) -> [u64; 11] {
    [
        d.porosity,
        d.void_ratio,
        d.coordination,
        d.mechanical_coordination,
        d.fabric_xx,
        d.fabric_yy,
        d.fabric_xy,
        d.anisotropy,
        d.fabric_direction,
        d.sliding_fraction,
        d.mean_rotation,
    ]
    .map(f64::to_bits)
}

/// Everything of an answer that is a function of (committed state, target), as bits: stress,
/// tangent, steps, contacts and the descriptors (the wall time is not).
fn answer_bits(r: &MicroResponse) -> (Vec<u64>, u64, u32, [u64; 11]) {
    let d = r.diagnostics.descriptors.as_ref().expect("a DEM answer carries descriptors");
    let v = r.stress.iter().chain(r.tangent.iter().flatten()).map(|x| x.to_bits()).collect();
    (v, r.diagnostics.steps, r.diagnostics.contacts, bits(d))
}

/// Three load steps, each solved, then committed, on `m`; the answers of every step.
fn program(m: &mut dyn Material) -> Vec<Vec<MicroResponse>> {
    (1..=3)
        .map(|step| {
            let r = m.evaluate(TrialId { step, iteration: 0 }, &inputs(2e-3 * step as f64));
            let r = r.unwrap();
            m.commit(step).unwrap();
            r
        })
        .collect()
}

#[test]
fn descriptors_cross_grpc_with_the_bits_of_the_direct_path() {
    let spec = spec();
    let mut direct = DirectDem::new(&spec, &ids()).unwrap();
    let expected = program(&mut direct);

    let config = PoolConfig { in_process_duplex: true, ..common::test_config() };
    let mut pool = Pool::in_process(1, config, |_| cosdem_worker::Dem).unwrap();
    let request = AssemblyRequest {
        spec_json: serde_json::to_vec(&spec).unwrap(),
        boundary: BoundaryKind::Penalty,
        disc_count_hint: spec.disc_count_hint(),
    };
    pool.create_assemblies(&ids(), &request).unwrap();
    let got = program(&mut pool);

    assert_eq!(got.len(), expected.len());
    for (step, (g, e)) in got.iter().zip(&expected).enumerate() {
        for (k, (g, e)) in g.iter().zip(e).enumerate() {
            assert_eq!(answer_bits(g), answer_bits(e), "step {}, point {k}", step + 1);
        }
    }
    // Not trivially equal: the loading moved the micro-structure.
    let first = expected[0][0].diagnostics.descriptors.unwrap();
    let last = expected[2][2].diagnostics.descriptors.unwrap();
    assert!(last.porosity < first.porosity, "{} -> {}", first.porosity, last.porosity);
    assert_ne!(last.mean_rotation, 0.0);
    assert!(last.coordination > 0.0 && last.anisotropy > 0.0);
}

/// Counts the Gauss points the observer saw with descriptors, and checks their values are in
/// range (porosity in (0, 1), fabric trace 1, sliding fraction in [0, 1]).
#[derive(Default)]
struct Seen {
    with: usize,
    without: usize,
}

impl cosdem_app::run::RunObserver for Seen {
    fn on_step(
        &mut self,
        _: &StepReport,
        s: &SolutionView<'_>,
        _: Option<&cosdem_app::output::run_dir::RunWriter>,
    ) -> cosdem_fem::Result<()> {
        for g in s.gauss_points {
            match &g.diagnostics.descriptors {
                Some(d) => {
                    self.with += 1;
                    assert!(d.porosity > 0.0 && d.porosity < 1.0, "{d:?}");
                    assert!((d.fabric_xx + d.fabric_yy - 1.0).abs() < 1e-12, "{d:?}");
                    assert!((0.0..=1.0).contains(&d.sliding_fraction), "{d:?}");
                }
                None => self.without += 1,
            }
        }
        Ok(())
    }
}

/// The quick example job, one load step through the run driver on an in-process worker: the
/// step observer (what writes `gauss.vtu`) sees descriptors at all 16 Gauss points.
#[test]
fn the_run_driver_hands_every_gauss_point_its_descriptors() {
    let job = common::quick(0.002);
    let mut seen = Seen::default();
    let outcome = common::run_in_process(&job, 1, 1, &mut seen);
    assert_eq!(outcome.steps, 1);
    assert_eq!((seen.with, seen.without), (16, 0));
}
