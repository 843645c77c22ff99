//! Bad input gives a clear error naming the field and the value; never a panic.

mod common;
use common::*;
use cosdem_common::MacroDeformation;
use cosdem_dem::{Assembly, AssemblySpec, NormalModel, PackingSpec};

fn err_of(spec: &AssemblySpec) -> String {
    Assembly::new(spec).expect_err("must be rejected").to_string()
}

/// Each bad field is named in the message, with its value.
#[test]
fn bad_specs_name_the_field() {
    let mut s = hex_spec(0.1, penalty());
    s.packing = PackingSpec::hexagonal(-0.005, 0.1);
    let e = err_of(&s);
    assert!(e.contains("packing.radius") && e.contains("-0.005"), "{e}");

    s.packing = PackingSpec::hexagonal(0.005, 0.02);
    assert!(err_of(&s).contains("packing.side"));

    let mut s = hex_spec(0.1, penalty());
    s.contact.normal = NormalModel::Linear { k_n: -1.0 };
    let e = err_of(&s);
    assert!(e.contains("contact.normal.k_n") && e.contains("-1"), "{e}");

    let mut s = hex_spec(0.1, penalty());
    s.density = f64::NAN;
    assert!(err_of(&s).contains("density"));

    let mut s = hex_spec(0.1, penalty());
    s.tangent = cosdem_dem::TangentKind::Adaptive { sliding: 1.5, strain: 1e-5 };
    let e = err_of(&s);
    assert!(e.contains("tangent.sliding") && e.contains("1.5"), "{e}");
    s.tangent = cosdem_dem::TangentKind::Adaptive { sliding: 0.05, strain: 0.0 };
    assert!(err_of(&s).contains("tangent.strain"));

    let mut s = hex_spec(0.1, penalty());
    s.packing = PackingSpec::Random {
        r_min: 0.004,
        r_max: 0.002,
        radii: vec![],
        side: 0.1,
        seed: 1,
        confining_stress: 1e5,
    };
    let e = err_of(&s);
    assert!(e.contains("r_min") && e.contains("inverted"), "{e}");

    let mut s = hex_spec(0.1, penalty());
    s.relaxation.safety = 1.5;
    assert!(err_of(&s).contains("relaxation.safety"));

    let mut s = hex_spec(0.1, penalty());
    s.boundary = cosdem_dem::BoundarySpec::Penalty { eps_f: 0.0, eps_c: 1e3 };
    assert!(err_of(&s).contains("boundary.eps_f"));
}

/// det(F) <= 0 and NaN targets are errors naming the problem; the assembly stays usable.
#[test]
fn bad_targets_are_errors() {
    let mut a = Assembly::new(&hex_spec(0.1, penalty())).unwrap();
    let e = a.solve(&grad([[-1.0, 0.0], [0.0, 0.0]])).unwrap_err().to_string();
    assert!(e.contains("det(F)"), "{e}");
    let mut t = MacroDeformation::IDENTITY;
    t.kappa[0] = f64::NAN;
    let e = a.solve(&t).unwrap_err().to_string();
    assert!(e.contains("k_x"), "{e}");
    assert!(a.solve(&iso(-1e-4)).is_ok());
}

/// Garbage bytes and unknown job-file fields are rejected with a message.
#[test]
fn bad_bytes_and_unknown_fields() {
    assert!(Assembly::from_bytes(b"nonsense").unwrap_err().to_string().contains("decode"));
    let a = Assembly::new(&hex_spec(0.1, penalty())).unwrap();
    let mut b = a.to_bytes();
    b.truncate(b.len() / 2);
    let err = Assembly::from_bytes(&b).unwrap_err();
    assert!(matches!(err, cosdem_dem::Error::Decode(_)), "{err}");
    let e = serde_json::from_str::<AssemblySpec>(r#"{"densty": 2000}"#).unwrap_err().to_string();
    assert!(e.contains("densty"), "{e}");
    let e = serde_json::from_str::<AssemblySpec>(
        r#"{"packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.1, "extra": 1}}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("extra"), "{e}");
    // The documented example of `spec.rs` parses to the defaults.
    let doc = r#"{
      "packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.1},
      "contact": {
        "normal": {"model": "linear", "k_n": 6.7e7},
        "tangential": {"model": "coulomb", "k_s": 3.4e7, "mu_s": 0.5, "c_s": 0.0},
        "rolling": {"model": "coulomb", "k_r": 25.0, "mu_r": 0.2, "c_r": 0.0}
      },
      "density": 2650.0,
      "boundary": {"kind": "penalty", "eps_f": 6.7e6, "eps_c": 1000.0},
      "relaxation": {"driver": {"kind": "cundall", "alpha": 0.7}, "criterion": "unbalanced_force",
                     "tolerance": 1e-4, "max_steps": 400000, "check_every": 10, "safety": 0.8,
                     "density_scale": 1.0, "skin": 0.5},
      "tangent": {"kind": "paper"},
      "warm_start": false
    }"#;
    assert_eq!(serde_json::from_str::<AssemblySpec>(doc).unwrap(), AssemblySpec::default());
    // Defaults round-trip through JSON.
    let s = AssemblySpec::default();
    let back: AssemblySpec = serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
    assert_eq!(back, s);
}
