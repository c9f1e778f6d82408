//! The `raytty` command: the interactive app, `render`, and the tools around them.

mod cli;
#[cfg(feature = "tui")]
mod tui;

fn main() -> std::process::ExitCode {
    cli::main().into()
}
