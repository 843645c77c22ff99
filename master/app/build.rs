//! Records the commit cosdem is built from (`COSDEM_COMMIT`, for the run directory's
//! provenance); nothing outside a git checkout or without git.

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .arg("-C")
            .arg(&root)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    if let Some(commit) = git(&["rev-parse", "HEAD"]) {
        println!("cargo:rustc-env=COSDEM_COMMIT={commit}");
    }
    // A new commit or a checkout changes HEAD or the branch it points at (a loose ref, or the
    // packed refs). Only files that exist are watched: a missing one would rerun this always.
    let branch =
        git(&["rev-parse", "--symbolic-full-name", "HEAD"]).filter(|r| r.starts_with("refs/"));
    let watched = ["HEAD".to_string(), "packed-refs".to_string()].into_iter().chain(branch);
    for name in watched {
        if let Some(path) = git(&["rev-parse", "--git-path", &name]) {
            let path = root.join(path);
            if path.is_file() {
                println!("cargo:rerun-if-changed={}", path.display());
            }
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
}
