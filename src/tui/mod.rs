//! The interactive app (the default cargo feature `tui`), in the Elm pattern: the model and
//! `update` in [`app`], the key mapping in [`keys`], the view in [`view`] and [`overlay`], and
//! the modules that do terminal I/O, [`terminal`] (the event loop) and [`tty`] (descriptors,
//! raw mode, restoring).

pub mod app;
pub mod detect;
pub mod input;
pub mod keys;
pub mod link;
pub mod overlay;
pub mod pixels;
pub mod terminal;
pub mod tty;
pub mod view;

pub use terminal::{Outcome, run};
