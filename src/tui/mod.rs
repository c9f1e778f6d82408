//! The interactive app (the default cargo feature `tui`), in the Elm pattern: the model and
//! `update` in [`app`], the key mapping in [`keys`], the view in [`view`] and [`overlay`], and
//! the one module that does terminal I/O, [`terminal`].

pub mod app;
pub mod input;
pub mod keys;
pub mod overlay;
pub mod terminal;
pub mod view;

pub use terminal::run;
