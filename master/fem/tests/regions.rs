//! `Regions`: a material per region. Routing must be invisible (each point gets exactly what
//! its own material answers, in the order asked), failures of several parts must be merged,
//! bad partitions refused, and a two-material bar must come out as two springs in series.

use cosdem_common::micro::AssemblyState;
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_fem::assembly::{Component, Field, GaussData};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::material::{
    ElasticCosserat, FailureInjector, Material, MaterialError, MaterialInput, Regions,
    RegionsError, TrialId,
};
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{
    Dirichlet, EdgeLoad, EdgeLoadKind, Loading, Model, Ramp, Solver, SolverSettings,
};
use std::sync::{Arc, Mutex};

const TRIAL: TrialId = TrialId { step: 1, iteration: 0 };

fn id(element: u32) -> GaussPointId {
    GaussPointId::new(element, 0)
}

/// A distinct, general deformation per point (all six strain components non-zero).
fn input(element: u32) -> MaterialInput {
    let s = 1e-3 * (1.0 + f64::from(element));
    MaterialInput {
        gauss_point: id(element),
        deformation: MacroDeformation::from_gradient(
            [[s, 0.3 * s], [-0.7 * s, 0.5 * s]],
            0.2 * s,
            [2.0 * s, -s],
        ),
    }
}

fn stiff() -> ElasticCosserat {
    ElasticCosserat::new(1e7, 0.25, 5e6, 0.01)
}

fn soft() -> ElasticCosserat {
    ElasticCosserat::new(3e5, 0.3, 1e5, 0.02)
}

/// Points 0, 2, 4 stiff, 1, 3, 5 soft.
fn two_elastic() -> Regions {
    Regions::new(vec![
        (Box::new(stiff()), vec![id(0), id(2), id(4)]),
        (Box::new(soft()), vec![id(1), id(3), id(5)]),
    ])
    .unwrap()
}

fn alone(mut m: ElasticCosserat, i: MaterialInput) -> MicroResponse {
    m.evaluate(TRIAL, &[i]).unwrap().remove(0)
}

/// Each answer equals, bit for bit, what the owning material gives for that point alone,
/// with the inputs interleaving the parts in a shuffled order (exact: routing does no
/// arithmetic).
#[test]
fn routed_answers_equal_each_material_alone_bit_for_bit() {
    let mut regions = two_elastic();
    assert!(regions.is_symmetric());
    let order = [3, 0, 5, 4, 1, 2];
    let inputs: Vec<MaterialInput> = order.iter().map(|&e| input(e)).collect();
    let out = regions.evaluate(TRIAL, &inputs).unwrap();
    assert_eq!(out.len(), inputs.len());
    for (i, r) in inputs.iter().zip(&out) {
        let own = if i.gauss_point.element % 2 == 0 { stiff() } else { soft() };
        assert_eq!(*r, alone(own, *i), "{}", i.gauss_point);
    }
    assert_eq!(regions.owner(id(3)), Some(1));
    assert_eq!(regions.owner(id(9)), None);
}

/// Records the order of the points it is asked about.
struct Recorder {
    seen: Arc<Mutex<Vec<GaussPointId>>>,
    states: Vec<GaussPointId>,
    unavailable: bool,
}

impl Material for Recorder {
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        if self.unavailable {
            return Err(MaterialError::Unavailable("pool lost".into()));
        }
        self.seen.lock().unwrap().extend(inputs.iter().map(|i| i.gauss_point));
        stiff().evaluate(trial, inputs)
    }
    fn commit(&mut self, _: u64) -> Result<(), MaterialError> {
        self.seen.lock().unwrap().push(GaussPointId::new(99, 0));
        Err(MaterialError::Unavailable("commit refused".into()))
    }
    fn rollback(&mut self) -> Result<(), MaterialError> {
        Ok(())
    }
    fn committed_states(&mut self) -> Result<Option<Vec<AssemblyState>>, MaterialError> {
        Ok((!self.states.is_empty()).then(|| {
            let state = |&id| AssemblyState { id, committed_step: 1, state: vec![], disc_count: 0 };
            self.states.iter().map(state).collect()
        }))
    }
    fn restore_states(&mut self, states: Vec<AssemblyState>) -> Result<(), MaterialError> {
        self.seen.lock().unwrap().extend(states.iter().map(|s| s.id));
        Ok(())
    }
}

fn recorder(seen: &Arc<Mutex<Vec<GaussPointId>>>, states: &[u32]) -> Box<dyn Material> {
    let states = states.iter().map(|&e| id(e)).collect();
    Box::new(Recorder { seen: seen.clone(), states, unavailable: false })
}

/// A part sees its points in the order of the inputs; commit reaches every part even after
/// the first fails and returns that first error.
#[test]
fn order_within_a_part_is_kept_and_commit_reaches_every_part() {
    let (a, b) = (Arc::new(Mutex::new(vec![])), Arc::new(Mutex::new(vec![])));
    let mut regions = Regions::new(vec![
        (recorder(&a, &[]), vec![id(0), id(1), id(2)]),
        (recorder(&b, &[]), vec![id(3), id(4)]),
    ])
    .unwrap();
    let inputs: Vec<MaterialInput> = [4, 2, 0, 3, 1].iter().map(|&e| input(e)).collect();
    regions.evaluate(TRIAL, &inputs).unwrap();
    assert_eq!(*a.lock().unwrap(), [id(2), id(0), id(1)]);
    assert_eq!(*b.lock().unwrap(), [id(4), id(3)]);
    let err = regions.commit(1).unwrap_err().to_string();
    assert!(err.contains("commit refused"), "{err}");
    assert_eq!(a.lock().unwrap().last(), Some(&GaussPointId::new(99, 0)));
    assert_eq!(b.lock().unwrap().last(), Some(&GaussPointId::new(99, 0)));
}

/// Two failing parts report all their failed points in one `GaussPoints` error (so a step
/// cut sees them all); an unavailable part wins over them; a point of no part is named.
#[test]
fn failures_of_several_parts_are_merged() {
    let failing = |targets: Vec<GaussPointId>| -> Box<dyn Material> {
        Box::new(FailureInjector::new(stiff(), targets, 1e-9))
    };
    let mut regions = Regions::new(vec![
        (failing(vec![id(1)]), vec![id(0), id(1)]),
        (Box::new(soft()), vec![id(2)]),
        (failing(vec![id(3), id(4)]), vec![id(3), id(4)]),
    ])
    .unwrap();
    let inputs: Vec<MaterialInput> = (0..5).map(input).collect();
    match regions.evaluate(TRIAL, &inputs) {
        Err(MaterialError::GaussPoints(points)) => {
            let ids: Vec<GaussPointId> = points.iter().map(|p| p.0).collect();
            assert_eq!(ids, [id(1), id(3), id(4)]);
        }
        other => panic!("expected the merged failures, got {other:?}"),
    }

    let seen = Arc::new(Mutex::new(vec![]));
    let lost = Box::new(Recorder { seen, states: vec![], unavailable: true });
    let mut regions =
        Regions::new(vec![(failing(vec![id(0)]), vec![id(0)]), (lost, vec![id(1)])]).unwrap();
    let err = regions.evaluate(TRIAL, &[input(0), input(1)]).unwrap_err();
    assert!(matches!(err, MaterialError::Unavailable(_)), "{err}");

    let err = two_elastic().evaluate(TRIAL, &[input(0), input(7)]).unwrap_err();
    match err {
        MaterialError::GaussPoints(p) => {
            assert_eq!(p.iter().map(|p| p.0).collect::<Vec<_>>(), [id(7)])
        }
        other => panic!("expected the orphan point, got {other}"),
    }
}

/// A point in two parts and a part without points are refused, naming the point and parts.
#[test]
fn overlap_and_empty_parts_are_refused() {
    let err = Regions::new(vec![
        (Box::new(stiff()), vec![id(0), id(1)]),
        (Box::new(soft()), vec![id(2), id(1)]),
    ])
    .unwrap_err();
    assert_eq!(err, RegionsError::Overlap { id: id(1), first: 0, second: 1 });
    let msg = err.to_string();
    assert!(msg.contains("element 1 gauss point 0") && msg.contains("part 0"), "{msg}");

    let err = Regions::new(vec![(Box::new(stiff()), vec![id(0)]), (Box::new(soft()), vec![])])
        .unwrap_err();
    assert_eq!(err, RegionsError::Empty { part: 1 });
    assert!(err.to_string().contains("part 1"), "{err}");
}

/// Checkpoint states: `None` when no part has any; else all of them sorted by point; on
/// restore each part gets its own, and a state of an unknown point is refused by name.
#[test]
fn committed_states_are_sorted_and_restored_to_their_owners() {
    assert!(two_elastic().committed_states().unwrap().is_none());
    let (a, b) = (Arc::new(Mutex::new(vec![])), Arc::new(Mutex::new(vec![])));
    let mut regions = Regions::new(vec![
        (recorder(&a, &[4, 0]), vec![id(0), id(4)]),
        (Box::new(soft()), vec![id(2)]),
        (recorder(&b, &[3, 1]), vec![id(1), id(3)]),
    ])
    .unwrap();
    let states = regions.committed_states().unwrap().unwrap();
    let ids: Vec<GaussPointId> = states.iter().map(|s| s.id).collect();
    assert_eq!(ids, [id(0), id(1), id(3), id(4)]);
    regions.restore_states(states.clone()).unwrap();
    assert_eq!(*a.lock().unwrap(), [id(0), id(4)]);
    assert_eq!(*b.lock().unwrap(), [id(1), id(3)]);

    let mut stray = states;
    stray[0].id = id(8);
    let err = regions.restore_states(stray).unwrap_err().to_string();
    assert!(err.contains("element 8 gauss point 0"), "{err}");
    assert_eq!(a.lock().unwrap().len(), 2, "nothing restored after the refusal");
}

/// A bar `[0, 2] x [0, 0.5]` of stiff (`x < 1`) and soft material with `nu = 0`, pulled by a
/// traction `s` on the right edge, held by `u_x = 0` on the left: the exact field is
/// `u_x` piecewise linear (slope `s / 2 G` in each part, the plane-strain modulus being `2 G`
/// when `nu = 0`), `u_y = w = 0`, so the right end moves `s (1 / 2 G1 + 1 / 2 G2)` (two
/// springs in series). The interface lies on element edges, so the quadratic elements hold
/// the exact field and one Newton step of the linear materials reproduces it up to the
/// round-off of the linear solve (about 1e-15 of the end displacement here). The tolerance,
/// 1e-9 relative to the end displacement, leaves room for that loss of digits on other
/// platforms and solver settings (condition number ~1e6 from the stiffness ratio 10, the mesh
/// and the micro-rotation dofs), while a point routed to the wrong material changes the end
/// displacement by tens of percent.
#[test]
fn two_material_bar_stretches_as_springs_in_series() {
    let (g1, g2, s) = (1e7, 1e6, 1e4);
    for (kind, rule) in
        [(ElementKind::Q8, QuadratureRule::Gauss2x2), (ElementKind::Q9, QuadratureRule::Gauss3x3)]
    {
        let mesh = Mesh::rectangle(kind, 2.0, 0.5, 4, 2, [0.0, 0.0]).unwrap();
        let gauss = GaussData::new(&mesh, rule).unwrap();
        let (mut left, mut right) = (vec![], vec![]);
        for g in 0..gauss.len() {
            let c = mesh.element_coords(gauss.id(g).element as usize);
            let x = c[..4].iter().map(|p| p[0]).sum::<f64>() / 4.0;
            if x < 1.0 { &mut left } else { &mut right }.push(gauss.id(g));
        }
        let mut regions = Regions::new(vec![
            (Box::new(ElasticCosserat::new(g1, 0.0, 0.5 * g1, 0.05)), left),
            (Box::new(ElasticCosserat::new(g2, 0.0, 0.5 * g2, 0.05)), right),
        ])
        .unwrap();
        let loading = Loading {
            dirichlet: vec![
                Dirichlet::new("left", Component::Ux, 0.0),
                Dirichlet::new("bottom_left", Component::Uy, 0.0),
            ],
            edge_loads: vec![EdgeLoad {
                set: "right".into(),
                kind: EdgeLoadKind::Traction([s, 0.0]),
                ramp: Ramp::Linear,
            }],
            ..Default::default()
        };
        let model =
            Model { mesh, field: Field::Cosserat, rule, loading, kinematics: Default::default() };
        let settings = SolverSettings { steps: 1, ..Default::default() };
        let mut solver = Solver::new(model, settings).unwrap();
        solver.run(&mut regions, &mut ()).unwrap();
        let view = solver.solution();
        let end = s / (2.0 * g1) + s / (2.0 * g2);
        let exact = |x: f64| {
            if x <= 1.0 { s * x / (2.0 * g1) } else { s / (2.0 * g1) + s * (x - 1.0) / (2.0 * g2) }
        };
        for (n, p) in view.mesh.nodes.iter().enumerate() {
            let u = &view.dofs[3 * n..3 * n + 3];
            let expect = [exact(p[0]), 0.0, 0.0];
            for c in 0..3 {
                let err = (u[c] - expect[c]).abs();
                assert!(
                    err <= 1e-9 * end,
                    "{kind:?} node {n} at {p:?} dof {c}: {u:?} vs {expect:?}"
                );
            }
        }
    }
}
