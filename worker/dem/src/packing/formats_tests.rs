//! Tests of the packing file formats: round trips to the last bit, every refusal naming the
//! file, the line and the value, and the hexagonal closed form.

use super::*;
use crate::packing::hexagonal;
use crate::spec::Lattice;

const OPT: ReadOptions = ReadOptions { density: 2650.0, periodic: false };

/// A polydisperse packing with awkward numbers (no short decimal form) and no overlaps.
fn awkward() -> Packing {
    let (mut x, mut y, mut r) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..7 {
        for i in 0..9 {
            let k = (i + 9 * j) as f64;
            r.push(0.001 * (1.0 + (k * 0.7).sin().abs() / 3.0));
            x.push(0.003 + 0.0041 * i as f64 + 1e-7 * (k * 1.3).cos());
            y.push(0.003 + 0.0041 * j as f64 + 1e-7 * (k * 2.1).sin());
        }
    }
    Packing { x, y, r, lx: 0.04 + 1.0 / 3.0 * 1e-3, ly: 0.0317 }
}

/// Bit equality of two packings (`==` would also accept -0.0 for 0.0).
fn same_bits(a: &Packing, b: &Packing) {
    let bits = |v: &[f64]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.x), bits(&b.x));
    assert_eq!(bits(&a.y), bits(&b.y));
    assert_eq!(bits(&a.r), bits(&b.r));
    assert_eq!((a.lx.to_bits(), a.ly.to_bits()), (b.lx.to_bits(), b.ly.to_bits()));
}

/// Written then read, a packing is the same to the last bit, in both formats.
#[test]
fn write_then_read_gives_the_same_bits() {
    let p = awkward();
    let yade = read(&write_yade(&p), PackingFormat::Yade, "a.txt", &OPT).unwrap();
    same_bits(&p, &yade);
    let lammps = read(&write_lammps(&p, 2650.0), PackingFormat::Lammps, "a.data", &OPT).unwrap();
    same_bits(&p, &lammps);
}

/// A hexagonal packing exported and re-imported keeps its disc count, radii and solid
/// fraction. The solid fraction of the periodic hexagonal cell is the infinite arrangement's
/// `pi / (2 sqrt 3)` up to rounding (1e-12); the penalty square holds a finite lattice whose
/// fraction is lower by the empty margins along its edges, about `r / side` (0.05 for 20 discs
/// a side, checked against 0.1).
#[test]
fn a_hexagonal_packing_keeps_its_solid_fraction() {
    let hex = std::f64::consts::PI / (2.0 * 3f64.sqrt());
    let r = 0.005;
    for (p, tol) in [
        (hexagonal::periodic(r, 0.2, Lattice::default()), 1e-12),
        (hexagonal::square(r, 0.2, Lattice::default()), 0.1),
    ] {
        for text in [write_yade(&p), write_lammps(&p, 2650.0)] {
            let format =
                if text.starts_with('#') { PackingFormat::Yade } else { PackingFormat::Lammps };
            let q = read(&text, format, "hex", &ReadOptions { periodic: true, ..OPT }).unwrap();
            assert_eq!(q.r.len(), p.r.len());
            assert!(q.r.iter().all(|&v| v == r));
            let phi = q.solid_fraction();
            assert!(phi <= hex * (1.0 + 1e-12) && (phi - hex).abs() <= tol * hex, "{phi} vs {hex}");
        }
    }
}

/// A YADE file without cosdem's box comment (as YADE's `export.text` writes it) takes the
/// discs' bounding box as its region, shifted to the origin; `#` comments and blank lines are
/// skipped.
#[test]
fn a_plain_yade_file_takes_the_bounding_box() {
    let text = "#format x_y_z_r\n\n1.0 2.0 0.5 0.5\n2.0 2.0 0.5 0.5\n1.0 3.0 0.5 0.5\n\
                2.0 3.0 0.5 0.5\n";
    let p = read(text, PackingFormat::Yade, "plain.txt", &OPT).unwrap();
    assert_eq!(p.x, [0.5, 1.5, 0.5, 1.5]);
    assert_eq!(p.y, [0.5, 0.5, 1.5, 1.5]);
    assert_eq!((p.lx, p.ly), (2.0, 2.0));
}

/// A LAMMPS file with comments, other sections (Velocities), image flags and atoms out of
/// id order reads in file order with `r = diameter / 2`.
#[test]
fn a_lammps_file_with_other_sections_reads() {
    let text = "title\n\n4 atoms\n1 atom types\n-1 1 xlo xhi\n-1 1 ylo yhi\n-0.5 0.5 zlo zhi\n\n\
                Atoms # sphere\n\n3 1 0.5 2650 -0.5 -0.5 0 0 0 0\n1 1 0.5 2650 0.5 -0.5 0 1 0 0\n\
                2 1 0.5 2650 -0.5 0.5 0\n4 1 0.5 2650 0.5 0.5 0 # last\n\nVelocities\n\n\
                1 0 0 0 0 0 0\n";
    let p = read(text, PackingFormat::Lammps, "in.data", &OPT).unwrap();
    assert_eq!(p.x, [0.5, 1.5, 0.5, 1.5]);
    assert_eq!(p.r, [0.25; 4]);
    assert_eq!((p.lx, p.ly), (2.0, 2.0));
}

/// The error of reading `text`, checked to name the file, the line (when given) and the
/// value.
fn refused(
    text: &str,
    format: PackingFormat,
    opt: &ReadOptions,
    line: usize,
    value: &str,
) -> String {
    let e = read(text, format, "bad.txt", opt).unwrap_err().to_string();
    assert!(e.contains("packing file bad.txt"), "{e}");
    if line > 0 {
        assert!(e.contains(&format!("line {line}:")), "{e}");
    }
    assert!(e.contains(value), "{e}");
    e
}

/// Four good YADE lines (no overlaps), line `k` replaced by `bad`.
fn yade_with(k: usize, bad: &str) -> String {
    let mut lines = ["0 0 0 1", "2 0 0 1", "0 2 0 1", "2 2 0 1", "4 0 0 1"];
    lines[k] = bad;
    lines.join("\n")
}

/// NaN, infinite and unreadable numbers, a zero or negative radius and a wrong column count
/// are refused with the line and the value.
#[test]
fn bad_numbers_are_refused() {
    refused(&yade_with(1, "NaN 0 0 1"), PackingFormat::Yade, &OPT, 2, "x = NaN");
    refused(&yade_with(2, "0 inf 0 1"), PackingFormat::Yade, &OPT, 3, "y = inf");
    refused(&yade_with(0, "0 0 0 1,5"), PackingFormat::Yade, &OPT, 1, "r = \"1,5\"");
    refused(&yade_with(3, "2 2 0 -1"), PackingFormat::Yade, &OPT, 4, "r = -1e0");
    refused(&yade_with(3, "2 2 0 0"), PackingFormat::Yade, &OPT, 4, "r = 0e0");
    refused(&yade_with(4, "4 0 0 1 7"), PackingFormat::Yade, &OPT, 5, "5 columns");
}

/// A disc off the first disc's plane is refused at its line; within 1e-6 r it passes.
#[test]
fn a_disc_off_the_plane_is_refused() {
    refused(&yade_with(2, "0 2 1e-5 1"), PackingFormat::Yade, &OPT, 3, "z = 1e-5");
    assert!(read(&yade_with(2, "0 2 1e-7 1"), PackingFormat::Yade, "ok", &OPT).is_ok());
}

/// Two discs overlapping by 2e-2 r are refused naming both lines; 5e-3 r passes.
#[test]
fn an_overlap_is_refused_naming_both_lines() {
    let e = refused(&yade_with(1, "1.98 0 0 1"), PackingFormat::Yade, &OPT, 2, "overlap 2");
    assert!(e.contains("line 1 overlap"), "{e}");
    assert!(read(&yade_with(1, "1.995 0 0 1"), PackingFormat::Yade, "ok", &OPT).is_ok());
}

/// An empty file, or one of comments only, or of three discs, is refused.
#[test]
fn too_few_discs_are_refused() {
    refused("", PackingFormat::Yade, &OPT, 0, "0 discs");
    refused("# nothing\n\n", PackingFormat::Yade, &OPT, 0, "0 discs");
    refused("0 0 0 1\n2 0 0 1\n4 0 0 1\n", PackingFormat::Yade, &OPT, 0, "3 discs");
    refused("", PackingFormat::Lammps, &OPT, 0, "no box");
}

/// A centre outside the `# cosdem box:` is refused at its line.
#[test]
fn a_centre_outside_the_box_is_refused() {
    let text = format!("# cosdem box: 0 5 -1 3\n{}", yade_with(4, "8 0 0 1"));
    refused(&text, PackingFormat::Yade, &OPT, 6, "centre (8e0, 0e0)");
}

/// A LAMMPS file of the good form with atom line `k` (of 4) replaced.
fn lammps_with(k: usize, bad: &str, header: &str) -> String {
    let mut atoms =
        ["1 1 2 2650 1 1 0", "2 1 2 2650 3 1 0", "3 1 2 2650 1 3 0", "4 1 2 2650 3 3 0"];
    atoms[k] = bad;
    format!("t\n\n{header}\n0 8 xlo xhi\n0 8 ylo yhi\n\nAtoms # sphere\n\n{}\n", atoms.join("\n"))
}

/// LAMMPS: a density other than the job's, another atom style, a triclinic box, a count that
/// differs from the header and a missing Atoms section are refused.
#[test]
fn lammps_refusals() {
    // Line 1 title, 2 blank, 3 header, 4-5 box, 6 blank, 7 Atoms, 8 blank, 9.. atoms.
    let e = refused(
        &lammps_with(1, "2 1 2 2500 3 1 0", "4 atoms"),
        PackingFormat::Lammps,
        &OPT,
        10,
        "density = 2500",
    );
    assert!(e.contains("2.65e3"), "{e}");
    let ok = lammps_with(1, "2 1 2 2650.001 3 1 0", "4 atoms");
    assert!(read(&ok, PackingFormat::Lammps, "ok", &OPT).is_ok());
    let atomic = lammps_with(0, "1 1 2 2650 1 1 0", "4 atoms").replace("# sphere", "# atomic");
    refused(&atomic, PackingFormat::Lammps, &OPT, 7, "Atoms # atomic");
    refused(
        &lammps_with(0, "1 1 2 2650 1 1 0", "0.5 0 0 xy xz yz"),
        PackingFormat::Lammps,
        &OPT,
        3,
        "xy = 0.5",
    );
    refused(
        &lammps_with(0, "1 1 2 2650 1 1 0", "5 atoms"),
        PackingFormat::Lammps,
        &OPT,
        3,
        "5 atoms",
    );
    refused(
        &lammps_with(2, "3 1 2 2650 1 3 0.1", "4 atoms"),
        PackingFormat::Lammps,
        &OPT,
        11,
        "z = 1e-1",
    );
    refused(
        &lammps_with(3, "4 1 -2 2650 3 3 0", "4 atoms"),
        PackingFormat::Lammps,
        &OPT,
        12,
        "r = -1e0",
    );
    refused(
        &lammps_with(3, "4 1 2 2650 3 3", "4 atoms"),
        PackingFormat::Lammps,
        &OPT,
        12,
        "6 columns",
    );
    refused("t\n0 1 xlo xhi\n0 1 ylo yhi\n", PackingFormat::Lammps, &OPT, 0, "no Atoms section");
}

/// An unknown format name is refused by the job's deserializer, naming it and the two
/// formats read.
#[test]
fn an_unknown_format_is_refused() {
    let e = serde_json::from_str::<PackingFormat>("\"xyz\"").unwrap_err().to_string();
    assert!(e.contains("xyz") && e.contains("yade") && e.contains("lammps"), "{e}");
}

/// The output formats parse from their names; another name is an error naming it.
#[test]
fn output_formats_parse_by_name() {
    assert_eq!("vtu".parse::<OutputFormat>(), Ok(OutputFormat::Vtu));
    assert_eq!("lammps".parse::<OutputFormat>().unwrap().extension(), "data");
    let e = "pdb".parse::<OutputFormat>().unwrap_err();
    assert!(e.contains("\"pdb\"") && e.contains("yade, lammps or vtu"), "{e}");
}
