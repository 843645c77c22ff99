use super::{Assembly, Reference, State};
use crate::boundary::penalty::boundary_layer;
use crate::broadphase::{self, PairList};
use crate::contact::Law;
use crate::error::{Error, Result};
use crate::integrate::timestep::{checked_step, driver_step, stable_penalty_masses};
use crate::integrate::{self, Dynamics, Work};
use crate::packing::explicit::first_overlap;
use crate::packing::{Packing, hexagonal, random};
use crate::spec::{
    AssemblySpec, BoundarySpec, Lattice, PackingSpec, RelaxationSpec, RollingModel, TangentialModel,
};
use cosdem_common::MacroDeformation;

pub(super) fn new(spec: &AssemblySpec) -> Result<Assembly> {
    spec.validate()?;
    let law = Law::from_params(&spec.contact);
    match &spec.packing {
        PackingSpec::Hexagonal { radius, side, orientation, overlap } => {
            let lattice = Lattice { orientation: *orientation, overlap: *overlap };
            let p = match spec.boundary {
                BoundarySpec::Penalty { .. } => hexagonal::square(*radius, *side, lattice),
                BoundarySpec::Periodic => hexagonal::periodic(*radius, *side, lattice),
            };
            let mut a = from_packing(spec, law, p)?;
            // An overlapping lattice is prestressed: in a periodic cell it is in equilibrium
            // by symmetry; cut to a square, the boundary springs' rest points balance it.
            if let BoundarySpec::Penalty { eps_f, eps_c } = spec.boundary
                && lattice.overlap > 0.0
            {
                prestress_reference(&mut a, eps_f, eps_c);
            }
            Ok(a)
        }
        PackingSpec::Random { .. } => {
            // The specimen is the material: generated with fixed relaxation settings, so that
            // it depends on the packing, the contact law and the boundary only, never on the
            // speed knobs (time-step safety, tolerance, driver, mass scaling, ...) its loading
            // is relaxed with. Then it takes the job's relaxation settings.
            let generation = generation_spec(spec);
            let a = random_assembly(&generation, law)?;
            respec(a, spec)
        }
        PackingSpec::Explicit { x, y, radii, lx, ly } => {
            let periodic = matches!(spec.boundary, BoundarySpec::Periodic);
            if periodic && let Some(o) = first_overlap(x, y, radii, *lx, *ly, true) {
                return Err(crate::error::invalid(
                    "packing.lx",
                    format!(
                        "discs {} and {} overlapping by {:?} across the cell",
                        o.i, o.j, o.overlap
                    ),
                    "two discs overlap through the periodic cell by more than 1e-2 of the smaller radius",
                ));
            }
            let mut a = from_packing(spec, law, Packing::explicit(x, y, radii, *lx, *ly))?;
            if let BoundarySpec::Penalty { eps_f, eps_c } = spec.boundary {
                prestress_reference(&mut a, eps_f, eps_c);
            }
            Ok(a)
        }
        PackingSpec::File { .. } => unreachable!("refused by validate"),
    }
}

/// The spec a random specimen is generated with: the job's, with the relaxation settings
/// replaced by the defaults (the Verlet skin kept: it changes no result, only the pair-list
/// rebuild rate) but the time-step safety pinned to [`GENERATION_SAFETY`], the paper tangent
/// and cold starts.
fn generation_spec(spec: &AssemblySpec) -> AssemblySpec {
    let mut g = spec.clone();
    g.relaxation = RelaxationSpec {
        skin: spec.relaxation.skin,
        safety: GENERATION_SAFETY,
        ..RelaxationSpec::default()
    };
    g.tangent = crate::spec::TangentKind::Paper;
    g.warm_start = false;
    g
}

/// The time-step safety random specimens are generated with: the default of the runs that
/// built every committed random table and study (it was the relaxation default until the
/// default became 0.8), so the specimens stay those bits whatever the loading's default.
pub const GENERATION_SAFETY: f64 = 0.5;

/// `a` driven by `spec` from now on: masses (mass scaling) and the time step (safety)
/// recomputed from it; geometry, committed state and contact histories kept.
fn respec(mut a: Assembly, spec: &AssemblySpec) -> Result<Assembly> {
    if a.spec == *spec {
        return Ok(a);
    }
    let (inv_m, inv_i, dt) = inertia(spec, &a.law, &a.refc.r, a.refc.area, &a.refc.boundary)?;
    a.refc.inv_m = inv_m;
    a.refc.inv_i = inv_i;
    a.dt = dt;
    a.spec = spec.clone();
    Ok(a)
}

/// Inverse masses and moments of inertia of discs of radii `r` (mass scaling applied) and
/// the relaxation's time step (safety times the critical step of the stiffest oscillator);
/// an unusable step is an error naming the parameter. A `boundary` disc whose penalty spring
/// would make the damped relaxation certainly diverge at that step gets the larger
/// relaxation mass or inertia of [`stable_penalty_masses`] (none does in a run that was
/// stable: its masses are unchanged).
fn inertia(
    spec: &AssemblySpec,
    law: &Law,
    r: &[f64],
    area: f64,
    boundary: &[u32],
) -> Result<(Vec<f64>, Vec<f64>, f64)> {
    let rho = spec.density * spec.relaxation.density_scale;
    let mut inv_m = Vec::with_capacity(r.len());
    let mut inv_i = Vec::with_capacity(r.len());
    for &r in r {
        let m = rho * std::f64::consts::PI * r * r;
        inv_m.push(1.0 / m);
        inv_i.push(2.0 / (m * r * r));
    }
    let r_min = r.iter().fold(f64::MAX, |a, &b| a.min(b));
    let (kf, kc) = match spec.boundary {
        BoundarySpec::Penalty { eps_f, eps_c } => (eps_f / area, eps_c / area),
        BoundarySpec::Periodic => (0.0, 0.0),
    };
    let m_min = rho * std::f64::consts::PI * r_min * r_min;
    let dt = spec.relaxation.safety
        * checked_step(law, m_min, 0.5 * m_min * r_min * r_min, r_min, kf, kc)?;
    let (h, gain) = driver_step(&spec.relaxation, dt);
    for &q in boundary {
        let q = q as usize;
        let disc = (1.0 / inv_m[q], 1.0 / inv_i[q], r[q]);
        let (m, i) = stable_penalty_masses(law, disc, (kf, kc), (h, gain, spec.relaxation.safety));
        (inv_m[q], inv_i[q]) = (1.0 / m, 1.0 / i);
    }
    Ok((inv_m, inv_i, dt))
}

/// An assembly at rest in the reference state of `p` (no histories, identity target).
/// Fails, naming the parameter, when the explicit time step is unusable.
pub(super) fn from_packing(spec: &AssemblySpec, law: Law, p: Packing) -> Result<Assembly> {
    let n = p.r.len();
    let r_min = p.r.iter().fold(f64::MAX, |a, &b| a.min(b));
    let r_max = p.r.iter().fold(0.0f64, |a, &b| a.max(b));
    let area = p.area();
    let boundary = match spec.boundary {
        BoundarySpec::Penalty { .. } => boundary_layer(&p.x, &p.y, p.lx, p.ly, 2.0 * r_max),
        BoundarySpec::Periodic => Vec::new(),
    };
    let (inv_m, inv_i, dt) = inertia(spec, &law, &p.r, area, &boundary)?;
    let refc = Reference {
        r: p.r.clone(),
        inv_m,
        inv_i,
        x0: p.x.clone(),
        y0: p.y.clone(),
        th0: vec![0.0; n],
        boundary,
        lx: p.lx,
        ly: p.ly,
        xc: [0.5 * p.lx, 0.5 * p.ly],
        area,
        r_min,
        r_max,
    };
    let dynamics = Dynamics::at_rest(p.x, p.y);
    let mut a = Assembly {
        spec: spec.clone(),
        law,
        refc,
        dt,
        committed: State {
            dynamics,
            pairs: PairList::default(),
            target: MacroDeformation::IDENTITY,
            relaxed: None,
        },
        trial: None,
        last_step: None,
        work: Work::default(),
    };
    let dom = a.domain(&MacroDeformation::IDENTITY);
    let skin = spec.relaxation.skin * r_min;
    let d = &a.committed.dynamics;
    a.committed.pairs = broadphase::build(&d.x, &d.y, &a.refc.r, skin, dom, &PairList::default());
    Ok(a)
}

/// Random packing (see [`crate::packing::random`]): periodic frictionless compression to the
/// confining stress, then the real contact law, then the requested boundary.
fn random_assembly(spec: &AssemblySpec, law: Law) -> Result<Assembly> {
    let PackingSpec::Random { r_min, r_max, radii, side, seed, confining_stress } = &spec.packing
    else {
        unreachable!()
    };
    let loose = random::loose(*r_min, *r_max, radii, *side, *seed)?;
    // Stage 1: frictionless periodic compression.
    let mut s1 = spec.clone();
    s1.boundary = BoundarySpec::Periodic;
    s1.contact.tangential = TangentialModel::None;
    s1.contact.rolling = RollingModel::None;
    s1.tangent = crate::spec::TangentKind::Paper;
    s1.warm_start = false;
    s1.relaxation.tolerance = 1e-3;
    s1.relaxation.max_steps = 4_000;
    s1.relaxation.predictor = crate::spec::Predictor::Affine;
    // FIRE relaxes the frictionless compression stages several times faster than Cundall.
    s1.relaxation.driver = crate::spec::Driver::fire();
    let mut a = from_packing(&s1, Law::from_params(&s1.contact), loose)?;
    let pressure = |s: &[f64; 6]| -0.5 * (s[0] + s[1]);
    let target = *confining_stress;
    let iso = |l: f64| MacroDeformation { f: [[l, 0.0], [0.0, l]], w: 0.0, kappa: [0.0; 2] };
    let (mut lo, mut hi) = (1.0f64, 0.0f64); // lo: below target pressure, hi: above
    let mut lam = 1.0f64;
    let mut found = false;
    for _ in 0..400 {
        lam *= 0.99;
        let resp = a.solve(&iso(lam))?;
        let p = pressure(&resp.stress);
        if p >= target {
            hi = lam;
            found = true;
            break;
        }
        a.commit();
        lo = lam;
    }
    if !found {
        return Err(Error::Packing(format!(
            "confining stress {target} Pa not reached after compressing to area ratio {:.3}",
            lam * lam
        )));
    }
    // Bisection on the cell stretch (from the committed state below the target). A stage
    // that hit its step cap is continued (commit, solve the same target again) until it
    // converges, so a pressure is accepted only at equilibrium.
    let settle = |a: &mut Assembly, lam: f64| -> Result<f64> {
        let mut resp = a.solve(&iso(lam))?;
        for _ in 0..25 {
            if resp.diagnostics.converged {
                break;
            }
            a.commit();
            resp = a.solve(&iso(lam))?;
        }
        Ok(pressure(&resp.stress))
    };
    let mut best = lo;
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        let p = settle(&mut a, mid)?;
        best = mid;
        if (p - target).abs() <= 0.02 * target {
            break;
        }
        if p < target {
            a.commit();
            lo = mid;
        } else {
            hi = mid;
        }
    }
    a.commit();
    // Stage 2: the compressed periodic configuration becomes the reference.
    let l = best * a.refc.lx;
    let d = &a.committed.dynamics;
    let mut p = Packing {
        x: d.x.clone(),
        y: d.y.clone(),
        r: a.refc.r.clone(),
        lx: l,
        ly: best * a.refc.ly,
    };
    let periodic = matches!(spec.boundary, BoundarySpec::Periodic);
    if !periodic {
        // Wrap into [0, lx) x [0, ly): contacts across the cut are dropped below.
        for k in 0..p.x.len() {
            p.x[k] -= (p.x[k] / p.lx).floor() * p.lx;
            p.y[k] -= (p.y[k] / p.ly).floor() * p.ly;
        }
    }
    let _ = l;
    let mut b = from_packing(spec, law, p)?;
    if let BoundarySpec::Penalty { eps_f, eps_c } = spec.boundary {
        prestress_reference(&mut b, eps_f, eps_c);
    }
    // With friction switched on and, for a penalty square, the contacts across the cut lost,
    // the relaxed stress differs from the target: bring it back by an isotropic stretch
    // (secant iteration on the contact tangent, each solve relaxed to the spec's tolerance),
    // then make that state the reference.
    let mut r = b.solve(&MacroDeformation::IDENTITY)?;
    let mut e = 0.0;
    for _ in 0..30 {
        let p = pressure(&r.stress);
        if r.diagnostics.converged && (p - target).abs() <= 0.02 * target {
            break;
        }
        let c = &r.tangent;
        // dp/de for Fbar = (1 + e) I (negative: compression raises p).
        let k = -0.5 * (c[0][0] + c[0][1] + c[1][0] + c[1][1]);
        if k < 0.0 {
            e += (target - p) / k;
        }
        r = b.solve(&iso(1.0 + e))?;
    }
    if e != 0.0 {
        b = rereference(&b, spec, law, 1.0 + e)?;
    }
    // Final relaxation at the reference with the full contact law.
    let resp = b.solve(&MacroDeformation::IDENTITY)?;
    b.commit();
    let p_final = pressure(&resp.stress);
    if p_final.is_nan() || p_final <= 0.0 {
        return Err(Error::Packing(format!(
            "final confining stress {p_final} Pa is not compressive"
        )));
    }
    Ok(b)
}

/// The trial state of `b` (relaxed at `Fbar = lam I`) as a new reference: region scaled by
/// `lam` about its centre, contact histories kept, penalty rest points placed by
/// [`prestress_reference`].
fn rereference(b: &Assembly, spec: &AssemblySpec, law: Law, lam: f64) -> Result<Assembly> {
    let st = b.trial.as_ref().unwrap_or(&b.committed);
    let (lx, ly) = (lam * b.refc.lx, lam * b.refc.ly);
    let sx = b.refc.xc[0] - 0.5 * lx;
    let sy = b.refc.xc[1] - 0.5 * ly;
    let d = &st.dynamics;
    let p = Packing {
        x: d.x.iter().map(|v| v - sx).collect(),
        y: d.y.iter().map(|v| v - sy).collect(),
        r: b.refc.r.clone(),
        lx,
        ly,
    };
    let mut c = from_packing(spec, law, p)?;
    let skin = spec.relaxation.skin * c.refc.r_min;
    let cd = &c.committed.dynamics;
    let dom = c.domain(&MacroDeformation::IDENTITY);
    c.committed.pairs = broadphase::build(&cd.x, &cd.y, &c.refc.r, skin, dom, &st.pairs);
    if let BoundarySpec::Penalty { eps_f, eps_c } = spec.boundary {
        prestress_reference(&mut c, eps_f, eps_c);
    }
    Ok(c)
}

/// Moves the rest points of the boundary particles' penalty springs so that, at Fbar = I, each
/// spring balances the net contact force and torque on its particle: `X_q = x_q - (V/eps_f)
/// f_q`, `th0_q = -(V/eps_c) tau_q`. The prestressed cut packing is then in equilibrium in its
/// reference state.
fn prestress_reference(b: &mut Assembly, eps_f: f64, eps_c: f64) {
    let law = b.law;
    let sys = b.system(&law, None, &MacroDeformation::IDENTITY);
    let mut d = b.committed.dynamics.clone();
    d.stop();
    let mut pairs = b.committed.pairs.clone();
    let mut work = Work::default();
    integrate::forces(&sys, &d, &mut pairs, &mut work, b.dt);
    let v = b.refc.area;
    for &q in &b.refc.boundary {
        let q = q as usize;
        b.refc.x0[q] = d.x[q] - v / eps_f * work.fx[q];
        b.refc.y0[q] = d.y[q] - v / eps_f * work.fy[q];
        if eps_c > 0.0 {
            b.refc.th0[q] = -v / eps_c * work.tq[q];
        }
    }
}
