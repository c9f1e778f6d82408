//! The `raytty` command: the interactive app, `render`, and the tools around them.

mod cli;
#[cfg(feature = "tui")]
mod tui;

use std::process::ExitCode;

fn main() -> ExitCode {
    // Work every frame needs first is done on another thread while this one parses the
    // command line and loads the scene, rather than when the scene or the first frame asks:
    // the CPU's features (std caches them; on a VM each CPUID traps, ~30 µs in all) and
    // rayon's threads (reading the CPU quota and spawning them, ~0.2 ms).
    std::thread::spawn(|| {
        #[cfg(target_arch = "x86_64")]
        std::hint::black_box(std::is_x86_feature_detected!("avx2"));
        rayon::current_num_threads()
    });
    cli::main()
}
