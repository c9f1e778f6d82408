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
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = cpus_to_run_on() {
        pool = pool.num_threads(n);
    }
    let pool = pool
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

/// How many threads the pool gets when `RAYON_NUM_THREADS` does not say: as many as the CPUs
/// this process may run on (its affinity mask, what `nproc` counts), from one system call.
/// Rayon's default asks `std::thread::available_parallelism`, which also reads the cgroup's CPU
/// quota, a dozen file-system calls into /proc and /sys: 0.19 ms of a 2×2 frame's 0.94 on this
/// project's VM (README, "How fast it traces"). So a quota is not read: where one is set below
/// the CPUs in the mask (a container's `--cpus`), `RAYON_NUM_THREADS` sets the count. `None`
/// leaves it to rayon: the variable set, the mask unreadable, or not Linux.
fn cpus_to_run_on() -> Option<usize> {
    if std::env::var_os("RAYON_NUM_THREADS").is_some() {
        return None;
    }
    #[cfg(target_os = "linux")]
    {
        // SAFETY: `set` is a `cpu_set_t` of the size given, written by the kernel; `CPU_COUNT`
        // only reads it.
        let count = unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            if libc::sched_getaffinity(0, std::mem::size_of_val(&set), &mut set) != 0 {
                return None;
            }
            libc::CPU_COUNT(&set)
        };
        usize::try_from(count).ok().filter(|&n| n > 0)
    }
    #[cfg(not(target_os = "linux"))]
    None
}
