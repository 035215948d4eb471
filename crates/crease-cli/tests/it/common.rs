//! Helpers shared by the command-line tests.

use std::path::{Path, PathBuf};

use assert_cmd::Command;

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
