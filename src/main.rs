//! The `raytty` command: the interactive app, `render`, and the tools around them.

mod cli;
#[cfg(feature = "tui")]
mod tui;

fn main() -> std::process::ExitCode {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    keep_freed_memory();
    cli::main().into()
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
