//! How a long bench reports how far it got. The library draws nothing itself: the binary hands
//! in a progress bar, tests and quiet callers [`NoProgress`].

/// A sink for progress: one task at a time, counted in steps.
pub trait Progress {
    /// A new task of `total` steps, `done` of them already done (a resumed reference).
    fn start(&mut self, label: &str, total: u64, done: u64);
    /// What the task is doing now (shown beside the bar).
    fn message(&mut self, _message: &str) {}
    /// `steps` more steps are done.
    fn advance(&mut self, steps: u64);
    /// The task is over: clear whatever was drawn.
    fn finish(&mut self);
}

/// Progress that goes nowhere.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&mut self, _label: &str, _total: u64, _done: u64) {}
    fn advance(&mut self, _steps: u64) {}
    fn finish(&mut self) {}
}
