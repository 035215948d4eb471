//! `crease`: the command-line tool (the library `crease_cli` does the work).

use std::process::ExitCode;

fn main() -> ExitCode {
    ExitCode::from(crease_cli::main_with_args(std::env::args_os()))
}
