//! The render's threads: the calling thread renders too, the pool's join as they can.

use std::sync::{Mutex, PoisonError};

use crate::shading::RayCounts;

/// Runs `work` on the calling thread and, at the same time, on as many other threads of the
/// current rayon pool as there are `units` of work left for them, and sums what they return.
/// The calling thread starts at once rather than waking the pool and waiting for it; a pool
/// thread joins when it wakes (one that wakes after the work is gone returns at once). `work`
/// shares the units out itself; it is told whether to take them from the back (the pool's
/// threads) or the front (the calling thread): then the two ends of a new image are first
/// touched (and zeroed by the kernel) by different threads at the same time, not one after the
/// other. With one unit the pool is not used (nor started).
pub(super) fn on_every_thread(units: usize, work: impl Fn(bool) -> RayCounts + Sync) -> RayCounts {
    if units <= 1 {
        return work(false);
    }
    let helpers = rayon::current_num_threads().min(units) - 1;
    let total = Mutex::new(RayCounts::default());
    let add = |n: RayCounts| *total.lock().unwrap_or_else(PoisonError::into_inner) += n;
    rayon::in_place_scope(|s| {
        for _ in 0..helpers {
            s.spawn(|_| add(work(true)));
        }
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
