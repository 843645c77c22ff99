//! The job-file reference, `docs/reference/job-file.md`, documents every key the schema
//! accepts, under its table's heading, and nothing else: a key cannot be added to the schema
//! without its row, and a row cannot outlive its key.
//!
//! The keys come from the schema itself (`common::schema`: serde's own lists of the keys,
//! variants and values each table accepts), down into every table, array of tables and
//! variant, the DEM assembly spec of `cosdem_dem::spec` included.
//!
//! The reference has one `### [table]` heading per table (`### Top level` for the top level)
//! with a row `` | `key` | default | meaning | `` per key; every variant and choice value
//! appears in backticks in its key's row.

mod common;

use common::{Schema, keys, schema};
use std::collections::BTreeMap;

/// The reference's sections: table path ("" for `### Top level`) to the rows of its key table
/// (key to the whole row).
fn reference(text: &str) -> BTreeMap<String, BTreeMap<String, String>> {
    let mut sections = BTreeMap::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        if let Some(heading) = line.strip_prefix("### ") {
            let table = if heading == "Top level" {
                String::new()
            } else {
                heading.trim_matches(|c| c == '[' || c == ']').to_string()
            };
            assert!(
                sections.insert(table.clone(), BTreeMap::new()).is_none(),
                "heading `{line}` appears twice"
            );
            current = Some(table);
        } else if line.starts_with("## ") || line.starts_with("# ") {
            current = None;
        } else if let (Some(table), Some(row)) = (&current, line.strip_prefix("| `")) {
            let key = row.split('`').next().unwrap().to_string();
            let rows: &mut BTreeMap<String, String> = sections.get_mut(table).unwrap();
            assert!(
                rows.insert(key.clone(), line.to_string()).is_none(),
                "[{table}] `{key}` twice"
            );
        }
    }
    sections
}

fn reference_file() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/reference/job-file.md");
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn heading(table: &str) -> String {
    if table.is_empty() { "### Top level".into() } else { format!("### [{table}]") }
}

/// The differences between the schema and the reference, one line each.
fn gaps(schema: &Schema, doc: &BTreeMap<String, BTreeMap<String, String>>) -> Vec<String> {
    let mut gaps = Vec::new();
    for (table, keys) in schema {
        let Some(rows) = doc.get(table) else {
            gaps.push(format!("no section `{}` for the table's keys {keys:?}", heading(table)));
            continue;
        };
        for (key, values) in keys {
            let Some(row) = rows.get(key) else {
                gaps.push(format!("`{}`: no row for the key `{key}`", heading(table)));
                continue;
            };
            for v in values {
                if !row.contains(&format!("`{v}`")) {
                    gaps.push(format!(
                        "`{}`: the row of `{key}` does not name `{v}`",
                        heading(table)
                    ));
                }
            }
        }
    }
    for (table, rows) in doc {
        let Some(keys) = schema.get(table) else {
            gaps.push(format!("`{}`: no such table in the schema", heading(table)));
            continue;
        };
        for key in rows.keys().filter(|k| !keys.contains_key(*k)) {
            gaps.push(format!("`{}`: the row `{key}` is no key of the schema", heading(table)));
        }
    }
    gaps
}

/// The walk sees the whole schema: the top level, the tables, the arrays of tables, the
/// variants of tagged tables (down into the DEM assembly spec), and the choices. Guards the
/// walk itself: were serde's messages to change, the walk would find nothing, and the
/// reference test would pass vacuously.
#[test]
fn the_walk_finds_every_kind_of_key() {
    let schema = schema();
    let has = |table: &str, key: &str| schema.get(table).is_some_and(|t| t.contains_key(key));
    assert!(has("", "accuracy") && has("", "workers"), "{schema:#?}");
    assert!(has("loading.pressure", "ramp"), "an array of tables: {schema:#?}");
    assert!(has("material", "shear_modulus") && has("material", "assembly"), "{schema:#?}");
    assert!(has("material.assembly.packing", "confining_stress"), "{schema:#?}");
    assert!(has("material.assembly.contact.normal", "c_n"), "{schema:#?}");
    assert!(has("material.assembly.relaxation.driver", "dt_max"), "{schema:#?}");
    assert!(has("material.assembly.tangent", "sliding"), "{schema:#?}");
    let values = |table: &str, key: &str| schema[table][key].iter().cloned().collect::<Vec<_>>();
    assert_eq!(values("material", "kind"), ["dem", "elastic"]);
    assert_eq!(values("mesh", "symmetry"), ["half-x", "half_x", "none", "quarter"]);
    assert_eq!(values("material.assembly.boundary", "kind"), ["penalty", "periodic"]);
    let n: usize = schema.values().map(BTreeMap::len).sum();
    assert!(n >= 100, "only {n} keys found: {schema:#?}");
    // 111 keys in 20 tables today, 102 distinct names (`kind`, `set`, `value`, ... recur).
    assert!(keys().len() >= 80, "{:?}", keys());
}

/// Every key of the schema has its row under its table's heading, every variant and choice
/// value is named in its key's row, and every row is a key of the schema.
#[test]
fn the_reference_documents_every_key() {
    let gaps = gaps_of(&schema(), &reference_file());
    assert!(
        gaps.is_empty(),
        "docs/reference/job-file.md and the schema differ:\n{}",
        gaps.join("\n")
    );
}

/// The check can fail: the reference with one row removed, one choice value renamed, or one
/// row of a key the schema does not have, is reported, naming the key (and only that).
#[test]
fn a_missing_row_a_missing_value_or_a_stale_row_is_reported() {
    let schema = schema();
    let text = reference_file();
    let before = gaps_of(&schema, &text);
    let with = |gap: &str| {
        let mut all = before.clone();
        all.push(gap.to_string());
        all.sort();
        all
    };
    let row = text.lines().find(|l| l.starts_with("| `mu_r` |")).expect("the row of mu_r");
    assert_eq!(
        gaps_of(&schema, &text.replace(&format!("{row}\n"), "")),
        with("`### [material.assembly.contact.rolling]`: no row for the key `mu_r`")
    );
    assert_eq!(
        gaps_of(&schema, &text.replace("`half_x`", "`half`")),
        with("`### [mesh]`: the row of `symmetry` does not name `half_x`")
    );
    let stale = "| `max_iterations` |";
    assert_eq!(
        gaps_of(&schema, &text.replace(stale, &format!("| `zz_old` | 1 | gone |\n{stale}"))),
        with("`### [newton]`: the row `zz_old` is no key of the schema")
    );
}

/// `[region.material]` is read as `[material]` is (the same struct), so its tables are
/// documented once, under `[material...]`: checks that each `region.material...` table has the
/// keys of its `material...` table, and leaves the copies out.
fn without_region_materials(schema: &Schema) -> Schema {
    let mut schema = schema.clone();
    let copies: Vec<String> =
        schema.keys().filter(|t| t.starts_with("region.material")).cloned().collect();
    for table in copies {
        let keys = schema.remove(&table).unwrap();
        let original = &table["region.".len()..];
        assert_eq!(schema.get(original), Some(&keys), "[{table}] differs from [{original}]");
    }
    schema
}

/// The differences between the schema and the reference text, sorted.
fn gaps_of(schema: &Schema, text: &str) -> Vec<String> {
    let mut gaps = gaps(&without_region_materials(schema), &reference(text));
    gaps.sort();
    gaps
}
