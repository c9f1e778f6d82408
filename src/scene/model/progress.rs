//! How far a model's load has got: the loader stores its step and counts, another thread reads
//! them (the binary draws a progress bar from them). The library itself prints nothing.

use std::sync::atomic::{AtomicU8, AtomicU64, Ordering};

/// A step of a load, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadStep {
    /// Reading the file (and the files it names).
    Reading,
    /// Parsing it into a model: [`LoadProgress::fraction`] says how much is done.
    Parsing,
    /// Checking the triangles and building the acceleration structure.
    Building,
}

impl LoadStep {
    /// What the step does, for people ("reading", "parsing", "building the BVH").
    pub fn label(self) -> &'static str {
        match self {
            LoadStep::Reading => "reading",
            LoadStep::Parsing => "parsing",
            LoadStep::Building => "building the BVH",
        }
    }
}

/// A load's step and, while parsing, its records done of all; shared by reference with a
/// thread that shows it. Updated every few thousand records, so it costs nothing measurable.
#[derive(Debug, Default)]
pub struct LoadProgress {
    step: AtomicU8,
    done: AtomicU64,
    total: AtomicU64,
}

impl LoadProgress {
    /// A load that has not started (its step is [`LoadStep::Reading`]).
    pub fn new() -> LoadProgress {
        LoadProgress::default()
    }

    /// The step the load is at.
    pub fn step(&self) -> LoadStep {
        match self.step.load(Ordering::Relaxed) {
            0 => LoadStep::Reading,
            1 => LoadStep::Parsing,
            _ => LoadStep::Building,
        }
    }

    /// The fraction of the step done, in [0, 1], when the step knows it.
    pub fn fraction(&self) -> Option<f64> {
        let total = self.total.load(Ordering::Relaxed);
        (self.step() == LoadStep::Parsing && total > 0)
            .then(|| (self.done.load(Ordering::Relaxed) as f64 / total as f64).min(1.0))
    }

    /// Moves on to `step`; `total` is how many units its [`LoadProgress::advance`] counts (0:
    /// unknown).
    pub(crate) fn start(&self, step: LoadStep, total: u64) {
        self.done.store(0, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
        self.step.store(step as u8, Ordering::Relaxed);
    }

    /// Sets the units done of the current step.
    pub(crate) fn set_done(&self, done: u64) {
        self.done.store(done, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_and_fractions() {
        let p = LoadProgress::new();
        assert_eq!((p.step(), p.fraction()), (LoadStep::Reading, None));
        p.start(LoadStep::Parsing, 200);
        p.set_done(50);
        assert_eq!((p.step(), p.fraction()), (LoadStep::Parsing, Some(0.25)));
        p.set_done(500);
        assert_eq!(p.fraction(), Some(1.0));
        p.start(LoadStep::Building, 0);
        assert_eq!((p.step(), p.fraction()), (LoadStep::Building, None));
    }
}
