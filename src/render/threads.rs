//! The render's threads: the calling thread renders too, the pool's join as they can, and a
//! pool thread just started waits for the first frame without sleeping.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

use crate::shading::RayCounts;

/// Set when a frame's work is first shared out: ends [`spin_until_work`].
static WORK_STARTED: AtomicBool = AtomicBool::new(false);

/// Waits without sleeping (yielding the CPU, never blocking) until the first frame's work is
/// shared out or `limit` has passed.
///
/// For a pool's thread just started, from its start handler: a CPU left idle may take
/// hundreds of microseconds to wake on a virtual machine, and a thread that goes to sleep has
/// to be woken when the frame starts; a thread that keeps running is there when the work
/// comes. It yields rather than spins: a new thread is sometimes put on the CPU of the thread
/// that made it, and there a spinning one would take half of that CPU from the thread that
/// is getting the frame ready, until the scheduler moves one of them (milliseconds). It
/// keeps a CPU busy, so `limit` should be a few milliseconds.
pub fn spin_until_work(limit: Duration) {
    let start = Instant::now();
    while !WORK_STARTED.load(Ordering::Relaxed) && start.elapsed() < limit {
        std::thread::yield_now();
    }
}

/// Ends [`spin_until_work`]: called once a frame's work is there for the pool to take.
pub(super) fn work_shared_out() {
    WORK_STARTED.store(true, Ordering::Relaxed);
}

/// Runs `work` on the calling thread and, at the same time, on as many other threads of the
/// current rayon pool as there are `units` of work left for them, and sums what they return.
/// The calling thread starts at once rather than waking the pool and waiting for it; a pool
/// thread joins when it wakes (one that wakes after the work is gone returns at once). `work`
/// shares the units out itself; it is told whether to take them from the back (the pool's
/// threads) or the front (the calling thread): then the two ends of a new image, each in its
/// own huge pages, are first touched (and zeroed by the kernel) by different threads at the
/// same time, not one after the other. With one unit the pool is not used (nor started).
pub(super) fn on_every_thread(units: usize, work: impl Fn(bool) -> RayCounts + Sync) -> RayCounts {
    if units <= 1 {
        work_shared_out();
        return work(false);
    }
    let helpers = rayon::current_num_threads().min(units) - 1;
    let total = Mutex::new(RayCounts::default());
    let add = |n: RayCounts| *total.lock().unwrap_or_else(PoisonError::into_inner) += n;
    rayon::in_place_scope(|s| {
        for _ in 0..helpers {
            s.spawn(|_| add(work(true)));
        }
        work_shared_out();
        add(work(false));
    });
    total.into_inner().unwrap_or_else(PoisonError::into_inner)
}

/// The next unit of `units` (a frame's bands) for a thread of [`on_every_thread`]: from the
/// back for the pool's threads, from the front for the calling thread.
pub(super) fn next_band<I: DoubleEndedIterator>(
    units: &Mutex<I>,
    from_back: bool,
) -> Option<I::Item> {
    let mut units = units.lock().unwrap_or_else(PoisonError::into_inner);
    if from_back {
        units.next_back()
    } else {
        units.next()
    }
}
