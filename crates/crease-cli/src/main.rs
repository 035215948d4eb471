//! `crease`: the command-line tool. A thin layer over the `crease` library: argument parsing,
//! progress display, JSON summaries and exit codes (0 ok, 1 failure, 2 usage error).

mod args;
mod commands;
mod ui;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = match args::Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            // clap prints help / version to stdout with code 0, usage errors with code 2.
            let _ = e.print();
            return ExitCode::from(e.exit_code().clamp(0, 255) as u8);
        }
    };
    ui::init_logging(cli.global.verbose, cli.global.quiet);
    if let Some(mut n) = cli.global.threads {
        // More threads than cores only costs memory and start-up time (10,000 threads did not
        // start `crease info` within a minute).
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        if n > cores {
            tracing::warn!("--threads {n}: this machine has {cores} cores; using {cores}");
            n = cores;
        }
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
        {
            eprintln!("error: cannot start {n} threads: {e}");
            return ExitCode::from(1);
        }
    }
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of our output went away (`crease info scan.ply | head -1`): stop quietly.
        Err(e) if ui::is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            let code = if e.downcast_ref::<ui::UsageError>().is_some() {
                2
            } else {
                1
            };
            eprintln!("error: {e:#}");
            ExitCode::from(code)
        }
    }
}
