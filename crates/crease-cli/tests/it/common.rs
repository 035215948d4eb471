//! Helpers shared by the command-line tests.

use std::path::{Path, PathBuf};

use assert_cmd::Command;

/// `../shared/data`; fails under `CI=true` when missing, else skips.
pub fn data_dir() -> Option<PathBuf> {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data");
    if d.is_dir() {
        return Some(d);
    }
    assert!(
        std::env::var("CI").map(|v| v != "true").unwrap_or(true),
        "CI=true but the shared test data is missing at {}",
        d.display()
    );
    eprintln!("skipping: shared data not found at {}", d.display());
    None
}

/// The `crease` binary built by cargo for this test run.
pub fn crease() -> Command {
    Command::cargo_bin("crease").expect("the crease binary is built")
}

/// Runs `crease ARGS -o DIR/NAME -q` (e.g. `["synth", "cube", "-n", "1000"]`) and returns the
/// output path.
pub fn synth(dir: &Path, args: &[&str], name: &str) -> PathBuf {
    let out = dir.join(name);
    crease()
        .args(args)
        .arg("-o")
        .arg(&out)
        .arg("-q")
        .assert()
        .success();
    out
}

/// A JSON document printed on stdout.
pub fn json_of(out: &[u8]) -> serde_json::Value {
    serde_json::from_slice(out).expect("--json prints valid JSON on stdout")
}

/// Runs `crease CMD INPUT -o OUTPUT EXTRA...` and returns its assertion handle.
pub fn run(cmd: &str, input: &Path, output: &Path, extra: &[&str]) -> assert_cmd::assert::Assert {
    crease()
        .arg(cmd)
        .arg(input)
        .arg("-o")
        .arg(output)
        .args(extra)
        .assert()
}
