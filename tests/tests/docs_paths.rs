//! The docs name only paths that exist. In `README.md`, `docs/theory.md`, `docs/guide/*.md`,
//! `docs/reference/*.md` and `docs/problems/*.md`:
//!
//! - every repository path in backticks (an inline span such as `master/fem/src/solve/newton.rs`,
//!   or a word of a fenced block such as the `examples/quick.toml` of a command) exists;
//! - every relative Markdown link `[text](path)` resolves from the file that holds it (its
//!   `#anchor` is not checked).
//!
//! A repository path is a word with a `/` whose first component is a top-level entry of the
//! repository (`master/`, `worker/`, `examples/`, `.ci/`, ...; not `target/` or `runs/`, which
//! `.gitignore` ignores, nor a run directory's `vtk/` or `plots/`). A placeholder component
//! (`<stem>`, `*`, `NNNNN`, `{a,b}`) ends the path: its directory must exist. `docs/notes/` is
//! not checked: dated notes name the paths of their time.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The top of the repository.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The documents checked, in a fixed order.
fn documents(root: &Path) -> Vec<PathBuf> {
    let mut docs = vec![root.join("README.md"), root.join("docs/theory.md")];
    for dir in ["docs/guide", "docs/reference", "docs/problems"] {
        let mut md: Vec<PathBuf> = std::fs::read_dir(root.join(dir))
            .unwrap_or_else(|e| panic!("{dir}: {e}"))
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "md"))
            .collect();
        md.sort();
        docs.extend(md);
    }
    docs
}

/// The names at the top of the repository, without `.git` and what `.gitignore` ignores there
/// (`/target`, `/runs`: build output and run directories, which a clone does not have).
fn top_level(root: &Path) -> BTreeSet<String> {
    let ignored: BTreeSet<String> = std::fs::read_to_string(root.join(".gitignore"))
        .unwrap_or_default()
        .lines()
        .filter_map(|l| l.trim().strip_prefix('/'))
        .map(|l| l.trim_end_matches('/').to_string())
        .collect();
    std::fs::read_dir(root)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != ".git" && !ignored.contains(n))
        .collect()
}

/// The code of a Markdown text, with the line it starts on: each inline code span, and each
/// line of a fenced block.
fn code(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            out.push((i + 1, line));
        } else {
            out.extend(line.split('`').skip(1).step_by(2).map(|span| (i + 1, span)));
        }
    }
    out
}

/// True for a component that stands for many names (`<stem>`, `*.toml`, `snap_NNNNN.vtu`).
fn placeholder(component: &str) -> bool {
    component.contains(['<', '>', '*', '{', '}', '[', ']', '|']) || component.contains("NNN")
}

/// The repository paths a piece of code names: its words with a `/` whose first component is
/// in `top`, cut before the first placeholder component.
fn repository_paths(code: &str, top: &BTreeSet<String>) -> Vec<String> {
    code.split(|c: char| c.is_whitespace() || "\"'(),;=".contains(c))
        .map(|w| w.trim_start_matches("./").trim_end_matches(['.', ':']))
        .filter(|w| w.contains('/') && !w.contains("://"))
        .filter(|w| top.contains(w.split('/').next().unwrap()))
        .map(|w| {
            let kept: Vec<&str> = w.split('/').take_while(|c| !placeholder(c)).collect();
            kept.join("/")
        })
        .collect()
}

/// The relative link targets of a Markdown text (`[text](target)`, images too), with their
/// line, without their `#anchor` or title; web addresses and anchors within the page left out.
fn relative_links(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        for piece in line.split("](").skip(1) {
            let Some(end) = piece.find(')') else { continue };
            let target = piece[..end].split_whitespace().next().unwrap_or("");
            let target = target.split('#').next().unwrap();
            if target.is_empty() || target.contains(':') {
                continue;
            }
            out.push((i + 1, target));
        }
    }
    out
}

/// Every path or link of `doc`'s `text` that does not exist, as `doc:line: what`.
fn missing(root: &Path, doc: &Path, text: &str, top: &BTreeSet<String>) -> Vec<String> {
    let name = doc.strip_prefix(root).unwrap_or(doc).display().to_string();
    let mut out = Vec::new();
    for (line, code) in code(text) {
        for path in repository_paths(code, top) {
            if !root.join(&path).exists() {
                out.push(format!("{name}:{line}: `{path}` does not exist"));
            }
        }
    }
    let dir = doc.parent().unwrap();
    for (line, target) in relative_links(text) {
        if !dir.join(target).exists() {
            out.push(format!("{name}:{line}: link ({target}) does not resolve"));
        }
    }
    out
}

#[test]
fn every_path_and_link_the_docs_name_exists() {
    let root = root();
    let top = top_level(&root);
    assert!(top.contains("master") && top.contains(".ci") && !top.contains("target"), "{top:?}");
    let mut problems = Vec::new();
    let mut named = 0;
    for doc in documents(&root) {
        let text = std::fs::read_to_string(&doc).unwrap();
        named += code(&text).iter().map(|(_, c)| repository_paths(c, &top).len()).sum::<usize>();
        problems.extend(missing(&root, &doc, &text, &top));
    }
    // The docs name well over a hundred repository paths: a checker that finds none is broken.
    assert!(named > 100, "only {named} repository paths found");
    assert!(
        problems.is_empty(),
        "{} wrong paths in the docs:\n{}",
        problems.len(),
        problems.join("\n")
    );
}

/// The checker finds what it must: a wrong path in a span and in a command, a placeholder's
/// missing directory, a broken relative link; and passes what it must not flag.
#[test]
fn the_checker_finds_wrong_paths_and_links() {
    let root = root();
    let top = top_level(&root);
    let doc = root.join("docs/guide/running.md");
    let text = "\
Solved in `master/fem/src/solve/newton.rs` and `master/fem/src/nowhere.rs`.
```sh
cosdem run examples/quick.toml --out runs/quick
cosdem run examples/missing.toml
```
Outputs `vtk/mesh_NNNNN.vtu`, `RUN/checkpoint.bin`, `target/release/cosdem`, `x = a/b`;
series in `examples/expected/<stem>.csv` and `docs/no-such-dir/<name>.md`.
See [running](running.md#top), [the job file](../reference/job-file.md),
[gone](../reference/gone.md), [web](https://rustup.rs) and [here](#anchor).
";
    let found = missing(&root, &doc, text, &top);
    assert_eq!(
        found,
        [
            "docs/guide/running.md:1: `master/fem/src/nowhere.rs` does not exist",
            "docs/guide/running.md:4: `examples/missing.toml` does not exist",
            "docs/guide/running.md:7: `docs/no-such-dir` does not exist",
            "docs/guide/running.md:9: link (../reference/gone.md) does not resolve",
        ]
    );
}
