//! End-to-end tests of the `crease` binary, linked into one test binary: one module per command
//! family (they were one binary each). `common` holds the shared helpers.
//!
//! Run one module with a filter, e.g. `cargo test -p crease-cli --test it sharp_cli::`.

mod common;

mod cli;
mod curvature_cli;
mod degenerate_cli;
mod edges_cli;
mod eval_cli;
mod fillets_cli;
mod lines_cli;
mod normals_cli;
mod reconstruct_cli;
mod segment_cli;
mod sharp_cli;
mod view_cli;
