//! MEASURE: the figures of `cosdem_job::admission`, measured from the real structures with a
//! counting allocator (this binary's `#[global_allocator]`). One test, run alone in its binary,
//! so no other test's allocations are counted.
//!
//! - DEM: hexagonal assemblies of about 2 000 and 8 000 discs are built, solved once at a small
//!   strain and committed (so the committed and the trial state and the work arrays exist),
//!   and held; the live heap per disc (the slope between the two sizes, so fixed costs drop
//!   out) is the figure per disc, contacts included at this packing's coordination. Also the
//!   bytes of the encoded state (`to_bytes`, what the master keeps per assembly).
//! - FE: elastic rectangles of 16 x 16 and 32 x 32 Q8 elements are built and solved for one
//!   step; the peak heap per element (slope) covers the mesh, Gauss-point data, the sparse
//!   matrix and its factorization.
//!
//! Run it with `cargo test -p cosdem-job --test admission_measure -- --nocapture` to see the
//! figures; it checks that the estimate's constants bound what it measures (and are within a
//! factor of 3 of it), so a change of the structures that outgrows them fails here.

// A counting allocator is the one way to see what the structures hold; it only forwards to
// the system allocator.
#![allow(unsafe_code)]

use cosdem_dem::{Assembly, AssemblySpec, PackingSpec};
use cosdem_fem::solve::Solver;
use cosdem_job::admission::{
    BYTES_PER_CONTACT, BYTES_PER_DISC, CONTACTS_PER_DISC, FE_BYTES_PER_ELEMENT,
    FE_BYTES_PER_ELEMENT_LOG2, FE_WORKSPACE_BYTES, RANDOM_BUILD_BYTES_PER_DISC,
    STATE_BYTES_PER_DISC,
};
use cosdem_job::{Job, fixtures};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let now = LIVE.fetch_add(l.size(), Relaxed) + l.size();
            PEAK.fetch_max(now, Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        LIVE.fetch_sub(l.size(), Relaxed);
    }
}

#[global_allocator]
static A: Counting = Counting;

/// What one assembly holds.
struct Held {
    /// Live heap bytes after a solve, a commit and a solve.
    live: f64,
    discs: usize,
    /// Contact pairs of the committed state.
    pairs: usize,
    /// Bytes of the encoded state.
    encoded: usize,
}

/// The peak heap bytes of building an assembly of `packing`, and what it holds.
fn assembly(packing: PackingSpec) -> (f64, Held) {
    let spec = AssemblySpec { packing, ..AssemblySpec::default() };
    let before = LIVE.load(Relaxed);
    PEAK.store(before, Relaxed);
    let mut a = Assembly::new(&spec).unwrap();
    let build = (PEAK.load(Relaxed) - before) as f64;
    let g = [[-1e-4, 0.0], [0.0, -1e-4]];
    let target = cosdem_common::MacroDeformation::from_gradient(g, 0.0, [0.0; 2]);
    a.solve(&target).unwrap();
    a.commit();
    a.solve(&target).unwrap();
    let held = Held {
        live: (LIVE.load(Relaxed) - before) as f64,
        discs: a.disc_count(),
        pairs: a.committed().pairs.len(),
        encoded: a.to_bytes().len(),
    };
    drop(a);
    (build, held)
}

/// Peak heap bytes of building and solving one step of an `n` x `n` elastic panel, and its
/// element count.
fn panel(n: usize) -> (f64, usize) {
    let text = fixtures::text("elastic-panel")
        .replace("nx = 2", &format!("nx = {n}"))
        .replace("ny = 2", &format!("ny = {n}"))
        .replace("steps = 4", "steps = 1");
    let job = Job::from_toml(&text, "j").unwrap();
    let base = LIVE.load(Relaxed);
    PEAK.store(base, Relaxed);
    let mut mat = job.elastic().unwrap();
    let mut solver = Solver::new(job.model().unwrap(), job.solver_settings().unwrap()).unwrap();
    solver.run(&mut mat, &mut ()).unwrap();
    let peak = PEAK.load(Relaxed) - base;
    drop(solver);
    (peak as f64, n * n)
}

#[test]
fn measured_figures() {
    let live = BYTES_PER_DISC + CONTACTS_PER_DISC * BYTES_PER_CONTACT;
    // Within a factor of 3 below the constant, and never above it.
    let bounded = |what: &str, measured: f64, constant: f64| {
        println!("{what}: measured {measured:.1}, counted {constant:.1}");
        assert!(
            measured <= constant && measured >= constant / 3.0,
            "{what}: {measured} vs {constant}"
        );
    };
    let hex = |side| PackingSpec::hexagonal(0.005, side);
    let random = |side| PackingSpec::Random {
        r_min: 0.004,
        r_max: 0.006,
        radii: vec![],
        side,
        seed: 1,
        confining_stress: 1e5,
    };
    for (name, small, large) in
        [("hexagonal", hex(0.25), hex(0.5)), ("random", random(0.25), random(0.5))]
    {
        let (s1, a1) = assembly(small);
        let (s2, a2) = assembly(large);
        let d = (a2.discs - a1.discs) as f64;
        println!(
            "{name}: {} and {} discs, {:.2} pairs per disc",
            a1.discs,
            a2.discs,
            a2.pairs as f64 / a2.discs as f64
        );
        bounded("live bytes per disc", (a2.live - a1.live) / d, live);
        bounded("pairs per disc", a2.pairs as f64 / a2.discs as f64, CONTACTS_PER_DISC);
        bounded(
            "encoded bytes per disc",
            (a2.encoded - a1.encoded) as f64 / d,
            STATE_BYTES_PER_DISC,
        );
        let build = (s2 - s1) / d;
        let extra = if name == "random" { RANDOM_BUILD_BYTES_PER_DISC } else { 0.0 };
        println!("build peak per disc: {build:.1}, counted {:.1}", live + extra);
        assert!(build <= live + extra, "{name}: build {build}");
    }
    // The dense kernels under faer's supernodal Cholesky (private-gemm) allocate one
    // thread-local workspace on first use, sized by the CPU's caches: 1.9 GB of address space
    // on a machine reporting a 300 MiB L3, once per thread whatever the mesh. A first solve
    // sets it up so that the panels below measure what grows with the mesh.
    panel(16);
    for n in [4, 8, 16, 32, 64, 128] {
        let (peak, elements) = panel(n);
        let e = elements as f64;
        let per_element = FE_BYTES_PER_ELEMENT + FE_BYTES_PER_ELEMENT_LOG2 * e.log2();
        println!(
            "{n} x {n} panel: peak {:.0} B per element, counted {per_element:.0} (+ workspace)",
            peak / e
        );
        assert!(peak <= FE_WORKSPACE_BYTES + e * per_element, "{n} x {n}: peak {peak}");
        if n >= 64 {
            // Large enough for the workspace to matter little.
            assert!(peak >= e * per_element / 3.0, "{n} x {n}: peak {peak}");
        }
    }
}
