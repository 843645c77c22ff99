//! The job file's fixed-length arrays (`mesh.origin = [x, y]`, `output.snapshots = [[element,
//! point], ...]`), read as lists whose length is checked: serde's own `[T; N]` reads the first
//! N elements and ignores the rest, so `origin = [0, 0, 1]` was taken for `[0, 0]`.

use serde::de::{Deserialize, Deserializer, Error};

/// `n` elements `what` (`"1 number"`, `"3 numbers"`).
fn count(n: usize, what: &str) -> String {
    if n == 1 { format!("1 {what}") } else { format!("{n} {what}s") }
}

/// `values` as an array of `N`, or an error naming `key`, the length found and the length
/// expected (`shape` shows what the elements mean, e.g. `[x, y]`).
fn exactly<T: Copy + Default, E: Error, const N: usize>(
    values: &[T],
    key: &str,
    shape: &str,
) -> Result<[T; N], E> {
    <[T; N]>::try_from(values).map_err(|_| {
        E::custom(format!(
            "`{key}` takes {} {shape}, found {}",
            count(N, "number"),
            count(values.len(), "number")
        ))
    })
}

/// `mesh.origin`: exactly two numbers `[x, y]`.
pub(crate) fn origin<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let values = Vec::<f64>::deserialize(d)?;
    exactly(&values, "mesh.origin", "[x, y] (m)")
}

/// `output.snapshots`: a list of pairs `[element, point]`.
pub(crate) fn snapshots<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[u32; 2]>, D::Error> {
    let lists = Vec::<Vec<u32>>::deserialize(d)?;
    lists
        .iter()
        .enumerate()
        .map(|(i, pair)| exactly(pair, &format!("output.snapshots[{i}]"), "[element, point]"))
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::{Job, fixtures};

    fn with(extra: &str) -> String {
        let panel = fixtures::text("elastic-panel");
        format!("{}\n{extra}\n", panel.replace("lx = 1.0", "lx = 1.0\norigin = ORIGIN"))
    }

    /// `origin = [0, 0, 1]` was read as `[0, 0]`; now any length but 2 is refused naming the
    /// key, the length found and the length expected, at the key's line.
    #[test]
    fn an_origin_of_the_wrong_length_is_refused_naming_the_key() {
        let job = Job::from_toml(&with("").replace("ORIGIN", "[1, -2.5]"), "j.toml").unwrap();
        assert_eq!(job.mesh.origin, [1.0, -2.5]);
        for (origin, found) in
            [("[0, 0, 1]", "3 numbers"), ("[0]", "1 number"), ("[]", "0 numbers")]
        {
            let text = with("").replace("ORIGIN", origin);
            let line = 1 + text.lines().position(|l| l.starts_with("origin")).unwrap();
            let err = Job::from_toml(&text, "j.toml").unwrap_err().to_string();
            assert!(err.contains("`mesh.origin` takes 2 numbers [x, y]"), "{origin}: {err}");
            assert!(err.contains(&format!("found {found}")), "{origin}: {err}");
            assert!(err.contains(&format!("line {line}")), "{origin}: {err}");
        }
    }

    /// `snapshots = [[0, 0, 7]]` was read as `[[0, 0]]`: every pair must have two numbers.
    #[test]
    fn a_snapshot_of_the_wrong_length_is_refused_naming_the_key() {
        let ok = with("[output]\nsnapshots = [[0, 1], [1, 3]]").replace("ORIGIN", "[0, 0]");
        assert_eq!(Job::from_toml(&ok, "j").unwrap().output.snapshots, [[0, 1], [1, 3]]);
        for (list, key, found) in [
            ("[[0, 0, 7]]", "output.snapshots[0]", "3 numbers"),
            ("[[0, 1], [2]]", "output.snapshots[1]", "1 number"),
        ] {
            let text = with(&format!("[output]\nsnapshots = {list}")).replace("ORIGIN", "[0, 0]");
            let err = Job::from_toml(&text, "j").unwrap_err().to_string();
            assert!(err.contains(&format!("`{key}` takes 2 numbers [element, point]")), "{err}");
            assert!(err.contains(&format!("found {found}")), "{list}: {err}");
        }
    }
}
