//! The `raytty` command: the interactive app, `render`, and the tools around them.

mod cli;
mod scene_arg;
#[cfg(feature = "tui")]
mod tui;

use std::process::ExitCode;

fn main() -> ExitCode {
    cli::main()
}
