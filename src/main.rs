//! The `raytty` command: the interactive app, `render`, and the tools around them.

mod cli;
#[cfg(feature = "tui")]
mod tui;

fn main() -> std::process::ExitCode {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    keep_freed_memory();
    join_the_pool();
    cli::main().into()
}

/// Makes this thread one of rayon's (the pool keeps rayon's thread count: `RAYON_NUM_THREADS`,
/// else the CPUs this process may use, this thread among them; nothing spins). A frame's
/// parallel passes then start on this thread at once; from a thread outside the pool each pass
/// (a denoised frame has ten) is handed over, and this thread sleeps until it is done: two
/// wake-ups on the frame's path per pass. Stage 6 denoised at 200×100, `raytty bench`, medians
/// of 5 interleaved rounds on the quiet 2-core VM, without → with: 11.12 → 8.00 ms (another
/// sitting of 4 rounds: 10.04 → 9.80); thread switches of the 200×100 bench 3335 → 1225.
/// This thread runs the pool's work only while it is in a rayon call, and with one thread it
/// is the whole pool: no other thread may call rayon while this one waits outside it (the
/// app's reader, writer and signal threads only do I/O).
fn join_the_pool() {
    // It fails only if a pool was built before, and nothing builds one before `main`.
    let built = rayon::ThreadPoolBuilder::new()
        .use_current_thread()
        .build_global();
    debug_assert!(built.is_ok(), "rayon's pool was built before main");
}

/// glibc hands a freed block of more than 128 KiB back to the system and trims the free top of
/// its heap, so a frame's buffers (the denoiser's planes: ~2 MB at 200×100) are faulted in
/// afresh every frame. Kept for the next frame instead, the denoiser of a 200×100 stage-6
/// frame takes 2.9 ms instead of 3.7 (539 page faults → 8; medians of 6 × 61 interleaved runs,
/// 2 threads): ~7 % of that frame in the app and the bench. (Other C libraries: their defaults.)
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn keep_freed_memory() {
    // glibc's largest threshold: bigger blocks (a big model's arrays) are still mapped.
    const KEEP: libc::c_int = 32 << 20;
    // SAFETY: mallopt sets the allocator's parameters; no other thread runs yet.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, KEEP);
        libc::mallopt(libc::M_TRIM_THRESHOLD, KEEP);
    }
}
