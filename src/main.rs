//! The `raytty` command: the interactive app, `render`, and the tools around them.

mod cli;
#[cfg(feature = "tui")]
mod tui;

use std::process::ExitCode;
use std::time::Duration;

fn main() -> ExitCode {
    // This thread is one of rayon's (`use_current_thread`): it renders its share of every
    // frame and takes part in every parallel pass, rather than handing the work over and
    // waiting, so the pool starts one thread fewer than there are CPUs (`RAYON_NUM_THREADS`
    // still sets the total) and no CPU is asked to run two of ours at once. The pool's other
    // threads start now, while this one parses the command line and loads the scene; the
    // first asks the CPU for its features (std caches them; on a VM each CPUID traps, ~30 µs
    // in all), then they wait without sleeping (yielding) until the first frame's work is
    // there, for at most 5 ms, so they are running when it comes (`spin_until_work`).
    let pool = rayon::ThreadPoolBuilder::new()
        .use_current_thread()
        .start_handler(|i| {
            #[cfg(target_arch = "x86_64")]
            if i == 1 {
                std::hint::black_box(std::is_x86_feature_detected!("avx2"));
            }
            raytty::render::spin_until_work(Duration::from_millis(5));
        })
        .build_global();
    // It fails only if a pool was already built, and nothing builds one before this.
    debug_assert!(pool.is_ok(), "rayon's pool was built before main");
    cli::main()
}
