//! Terminal plumbing: logging, progress spinners, usage errors, output-path checks.

use std::io::IsTerminal;
use std::path::Path;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// An error in how the command was called (exit code 2), as opposed to a failure (exit code 1).
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// A usage error as an `anyhow::Error`.
pub fn usage(msg: impl Into<String>) -> anyhow::Error {
    anyhow::Error::new(UsageError(msg.into()))
}

/// Sets up tracing on stderr: warnings by default, more with -v, errors only with --quiet.
/// `RUST_LOG` overrides.
pub fn init_logging(verbose: u8, quiet: bool) {
    let level = if quiet {
        "error"
    } else {
        match verbose {
            0 => "warn",
            1 => "info",
            2 => "debug",
            _ => "trace",
        }
    };
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(level));
    let builder = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::stderr().is_terminal())
        .with_target(false);
    // Timestamps help when following a long run with -v; a plain warning needs none.
    let _ = if verbose == 0 {
        builder.without_time().try_init()
    } else {
        builder.try_init()
    };
}

/// A spinner on stderr for one stage of work, shown only when stderr is a terminal (and not
/// `--quiet`), and only once the stage has run for a second. Logs the stage's time at info level.
pub struct Stage {
    name: String,
    start: Instant,
    bar: Option<ProgressBar>,
}

impl Stage {
    /// Starts a stage called `name`.
    pub fn start(name: &str, quiet: bool) -> Stage {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template("{spinner} {msg} {elapsed}")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            bar.set_message(name.to_string());
            // The first tick is drawn after a second, so quick stages never show a bar.
            bar.enable_steady_tick(Duration::from_millis(1000));
            bar
        });
        Stage {
            name: name.to_string(),
            start: Instant::now(),
            bar,
        }
    }

    /// Ends the stage and returns its duration in seconds.
    pub fn finish(self) -> f64 {
        let t = self.start.elapsed().as_secs_f64();
        if let Some(b) = self.bar {
            b.finish_and_clear();
        }
        tracing::info!("{}: {:.3} s", self.name, t);
        t
    }
}

/// Refuses to write `output` if it is one of the `inputs` (never overwrite the input file), or
/// if its folder does not exist or `output` is a folder: every command checks its outputs so
/// before it reads or computes anything.
pub fn ensure_not_input(output: &Path, inputs: &[&Path]) -> anyhow::Result<()> {
    let parent = output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !parent.is_dir() {
        anyhow::bail!(
            "{}: the folder {} does not exist; create it first",
            output.display(),
            parent.display()
        );
    }
    if output.is_dir() {
        anyhow::bail!(
            "{}: is a folder; give a file name to write",
            output.display()
        );
    }
    let out = canonical(output);
    for inp in inputs {
        if canonical(inp) == out || same_file(inp, output) {
            return Err(usage(format!(
                "{}: the output file is the input file; crease never overwrites its input, choose another output name",
                output.display()
            )));
        }
    }
    Ok(())
}

/// True when both paths exist and are the same file (device and inode): a hard link to the
/// input is the input.
#[cfg(unix)]
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &Path, _: &Path) -> bool {
    false
}

/// The canonical form of a path that may not exist yet (its parent canonicalised).
fn canonical(p: &Path) -> std::path::PathBuf {
    if let Ok(c) = p.canonicalize() {
        return c;
    }
    let parent = p
        .parent()
        .filter(|q| !q.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    match (parent.canonicalize(), p.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => p.to_path_buf(),
    }
}

/// Writes `text` to `path`, replacing it atomically (`crease::io::atomic`).
pub fn write_text(path: &Path, text: &str) -> anyhow::Result<()> {
    crease::io::atomic::replace(path, |tmp| {
        std::fs::write(tmp, text).map_err(|e| crease::Error::io(tmp, e))
    })?;
    Ok(())
}

/// Writes one line to stdout. A closed pipe (`crease info scan.ply | head -1`) is an error
/// that `main` ends on quietly; `println!` would panic there.
pub fn outln(args: std::fmt::Arguments) -> anyhow::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)?;
    out.write_all(b"\n")?;
    Ok(())
}

/// Writes text to stdout as it is (see [`outln`]).
pub fn out(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    std::io::stdout().lock().write_all(text.as_bytes())?;
    Ok(())
}

/// True when `e` comes from writing to a pipe whose reader has gone.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Prints `value` as pretty JSON on stdout.
pub fn print_json(value: &serde_json::Value) -> anyhow::Result<()> {
    outln(format_args!("{}", serde_json::to_string_pretty(value)?))
}
