//! The `crease` command-line tool as a library: [`main_with_args`] runs one command line, so
//! that the binary (`src/main.rs`), the Python package's `crease` console command and its
//! `crease.batch` run the very same code. A thin layer over the `crease` library: argument
//! parsing, progress display, JSON summaries and exit codes (0 ok, 1 failure, 2 usage error).

mod args;
mod commands;
mod ui;

use std::ffi::OsString;

use clap::Parser;

/// Why a command line failed: its exit code (1 failure, 2 usage error) and the message printed
/// on stderr (without the `error: ` prefix).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failure {
    /// The process exit code.
    pub code: u8,
    /// The message, naming the file and the problem.
    pub message: String,
}

/// Runs one command line (`args[0]` is the program name) and returns its exit code, having
/// printed what the binary prints (help, results, `error: ...` on stderr).
pub fn main_with_args<I, T>(args: I) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    match try_main_with_args(args) {
        Ok(()) => 0,
        Err(f) => {
            if !f.message.is_empty() {
                eprintln!("error: {}", f.message);
            }
            f.code
        }
    }
}

/// As [`main_with_args`], but the error is returned instead of printed. Help and version
/// requests print to stdout and succeed; an argument error prints clap's message and returns
/// code 2 with an empty message.
pub fn try_main_with_args<I, T>(args: I) -> Result<(), Failure>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match args::Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            // clap prints help / version to stdout with code 0, usage errors with code 2.
            let _ = e.print();
            return match e.exit_code() {
                0 => Ok(()),
                c => Err(Failure {
                    code: c.clamp(1, 255) as u8,
                    message: String::new(),
                }),
            };
        }
    };
    ui::init_logging(cli.global.verbose, cli.global.quiet);
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let threads = match cli.global.threads {
        // More threads than cores only costs memory and start-up time (10,000 threads did not
        // start `crease info` within a minute).
        Some(n) if n > cores => {
            tracing::warn!("--threads {n}: this machine has {cores} cores; using {cores}");
            Some(cores)
        }
        t => t,
    };
    // A pool of its own when --threads is given (the global pool can be set only once per
    // process, and a Python process may run many command lines).
    let result = match threads {
        Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
            Ok(pool) => pool.install(|| commands::run(cli)),
            Err(e) => {
                return Err(Failure {
                    code: 1,
                    message: format!("cannot start {n} threads: {e}"),
                })
            }
        },
        None => commands::run(cli),
    };
    match result {
        Ok(()) => Ok(()),
        // The reader of our output went away (`crease info scan.ply | head -1`): stop quietly.
        Err(e) if ui::is_broken_pipe(&e) => Ok(()),
        Err(e) => Err(Failure {
            code: if e.downcast_ref::<ui::UsageError>().is_some() {
                2
            } else {
                1
            },
            message: format!("{e:#}"),
        }),
    }
}
