//! The `raytty` command: the interactive app, `render`, and the tools around them.

mod cli;
#[cfg(feature = "tui")]
mod tui;

use std::process::ExitCode;

fn main() -> ExitCode {
    // Rayon's threads start on another thread while this one parses the command line and
    // loads the scene (reading the CPU quota and spawning them takes ~0.2 ms), rather than
    // when the first frame needs them.
    std::thread::spawn(rayon::current_num_threads);
    cli::main()
}
