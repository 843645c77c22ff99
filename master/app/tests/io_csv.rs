//! The CSV load-displacement writer: header once, one synced row per step, exact numbers.

mod io_support;

use cosdem_app::output::CsvWriter;
use io_support::scratch;

#[test]
fn rows_are_on_disk_as_soon_as_written() {
    let dir = scratch("csv-rows");
    let path = dir.join("load.csv");
    let mut csv =
        CsvWriter::create(&path, &["step", "displacement", "load_top", "load_bottom"]).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "step,displacement,load_top,load_bottom\n");
    let rows = [
        [1.0, 1e-3, 12345.678901234567, -12345.678901234567],
        [2.0, 2e-3, 1.0 / 3.0, f64::MIN_POSITIVE],
        [3.0, 0.30000000000000004, 6.02214076e23, -0.0],
    ];
    for (k, r) in rows.iter().enumerate() {
        csv.write_row(r).unwrap();
        // Read while the writer is still alive: every row is already in the file.
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), k + 2);
        assert!(text.ends_with('\n'));
        let back: Vec<f64> = lines[k + 1].split(',').map(|x| x.parse().unwrap()).collect();
        assert_eq!(back.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), r.map(f64::to_bits));
    }
    assert_eq!(csv.rows(), 3);
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.lines().nth(1), Some("1,0.001,12345.678901234567,-12345.678901234567"));
}

#[test]
fn bad_rows_and_columns_are_rejected() {
    let dir = scratch("csv-bad");
    let path = dir.join("load.csv");
    let mut csv = CsvWriter::create(&path, &["step", "load"]).unwrap();
    let err = csv.write_row(&[1.0]).unwrap_err().to_string();
    assert!(err.contains("load.csv") && err.contains("1 values for the 2 columns"), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "step,load\n");
    // Non-finite values are recorded, in a form Rust (and pandas) parse back.
    csv.write_row(&[1.0, f64::NAN]).unwrap();
    assert!(std::fs::read_to_string(&path).unwrap().ends_with("1,NaN\n"));

    // Bad headers are refused with the file and what is wrong with them.
    let refused = |columns: &[&str]| match CsvWriter::create(&dir.join("x.csv"), columns) {
        Ok(_) => panic!("columns {columns:?} were accepted"),
        Err(e) => e.to_string(),
    };
    let e = refused(&[]);
    assert!(e.contains("x.csv") && e.contains("at least one column"), "{e}");
    let e = refused(&["a", "a"]);
    assert!(e.contains("x.csv") && e.contains("column name \"a\" appears twice"), "{e}");
    let e = refused(&["a", ""]);
    assert!(e.contains("x.csv") && e.contains("column 1 has an empty name"), "{e}");
    // Names with commas or quotes are quoted.
    CsvWriter::create(&dir.join("q.csv"), &["load, top", "say \"hi\""]).unwrap();
    assert_eq!(
        std::fs::read_to_string(dir.join("q.csv")).unwrap(),
        "\"load, top\",\"say \"\"hi\"\"\"\n"
    );
}

#[test]
fn resume_drops_a_torn_row_and_appends() {
    let dir = scratch("csv-resume");
    let path = dir.join("load.csv");
    {
        let mut csv = CsvWriter::create(&path, &["step", "load"]).unwrap();
        csv.write_row(&[1.0, 10.0]).unwrap();
        csv.write_row(&[2.0, 20.0]).unwrap();
    }
    // A kill in the middle of a write leaves a partial last line.
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.push_str("3,3");
    std::fs::write(&path, &text).unwrap();

    let mut csv = CsvWriter::resume(&path, &["step", "load"]).unwrap();
    assert_eq!(csv.rows(), 2);
    csv.write_row(&[3.0, 30.0]).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "step,load\n1,10\n2,20\n3,30\n");

    let err = CsvWriter::resume(&path, &["step", "force"]).unwrap_err().to_string();
    assert!(err.contains("header"), "{err}");
    let mut fresh = CsvWriter::resume(&dir.join("new.csv"), &["a"]).unwrap();
    fresh.write_row(&[1.5]).unwrap();
    assert_eq!(std::fs::read_to_string(dir.join("new.csv")).unwrap(), "a\n1.5\n");
}
