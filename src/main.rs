//! The `raytty` command: the interactive app, `render`, and the tools around them.
// On Linux the process starts at `main` below rather than at std's: see `main`.
#![cfg_attr(all(target_os = "linux", not(test)), no_main)]

mod cli;
#[cfg(feature = "tui")]
mod tui;

use std::time::Duration;

/// The process's entry on Linux, in place of std's. Std's start-up, before its `main`, asks for
/// the main thread's stack bounds (glibc reads them from /proc/self/maps) and maps an
/// alternate signal stack to report a stack overflow: some 25 system calls, about 0.1 ms of
/// a 2×2 frame's 0.9 on this project's VM. What of it the program needs is done here as std
/// does it: SIGPIPE ignored (a closed pipe is an error to report, not a kill), and standard
/// descriptors that are closed opened on /dev/null (so that no file opened later takes their
/// number). A stack overflow of this thread then ends the process by SIGSEGV without std's
/// message. Arguments and the environment come as before (std reads them from glibc's
/// start-up). `std::process::exit` flushes stdout, as returning from std's `main` does.
#[cfg(all(target_os = "linux", not(test)))]
#[unsafe(no_mangle)]
extern "C" fn main(
    _argc: std::ffi::c_int,
    _argv: *const *const std::ffi::c_char,
) -> std::ffi::c_int {
    // SAFETY: plain system calls on this process's own signal disposition and descriptors.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_IGN);
        let mut fds = [0, 1, 2].map(|fd| libc::pollfd {
            fd,
            events: 0,
            revents: 0,
        });
        if libc::poll(fds.as_mut_ptr(), 3, 0) > 0 {
            // Lowest numbers first: each `open` takes the closed one.
            for fd in fds {
                if fd.revents & libc::POLLNVAL != 0
                    && libc::open(c"/dev/null".as_ptr(), libc::O_RDWR) == -1
                {
                    libc::abort();
                }
            }
        }
    }
    std::process::exit(run().into())
}

/// The entry elsewhere: std's start-up, then the program.
#[cfg(not(all(target_os = "linux", not(test))))]
fn main() -> std::process::ExitCode {
    run().into()
}

/// The program: starts the render threads, then runs the command line; its exit status.
fn run() -> u8 {
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
