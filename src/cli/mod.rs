//! Command-line parsing and the non-interactive commands. The exit code is chosen here, once:
//! 0 for success (a closed output pipe included), 1 for a failure while running, 2 for bad
//! input (clap's own usage errors are 2 as well), and for the app 128 + N after signal N
//! ([`signal_status`]; a dropped terminal counts as SIGHUP).

mod args;
mod bench;
mod loading;
mod progress;
mod render;
pub mod scene_arg;
mod tiles;

#[cfg(feature = "tui")]
use std::io::IsTerminal;
use std::io::{self, Write};

use clap::{CommandFactory, FromArgMatches};
use raytty::{ColorMode, Stage};

use args::*;
use bench::run_bench;
use render::{RenderColor, run_render, text_format, without_os_error};

/// Parses the command line, runs it, and maps the outcome to an exit status.
pub fn main() -> u8 {
    let cmd = Cli::command();
    // The app's keys, under `--help` (and `help`).
    #[cfg(feature = "tui")]
    let cmd = cmd.after_long_help(crate::tui::keys::help_text());
    let mut cmd = cmd;
    let matches = cmd.get_matches_mut();
    global_conflicts(&mut cmd, &matches).unwrap_or_else(|e| e.exit());
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    // `raytty --color 256 render` means what `raytty render --color 256` does.
    let color_given = (matches.value_source("color")
        == Some(clap::parser::ValueSource::CommandLine))
    .then_some(cli.color);
    let dumb = is_dumb(std::env::var("TERM").ok().as_deref());
    let no_color = std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty());
    let colorterm = std::env::var("COLORTERM").ok();
    let resolve = |c| resolve_color(c, dumb || no_color, colorterm.as_deref());
    let color = resolve(cli.color);
    let view = cli.view.view();
    let scene = cli.scene.as_deref().or(cli.file.as_deref());
    let term = std::env::var("TERM").ok();
    let program = std::env::var("TERM_PROGRAM").ok();
    let version = std::env::var("TERM_PROGRAM_VERSION").ok();
    let env = TermEnv {
        term: term.as_deref(),
        program: program.as_deref(),
        version: version.as_deref(),
        kitty: std::env::var_os("KITTY_WINDOW_ID").is_some(),
    };
    let result = match cli.command {
        Some(Command::Render(args)) => {
            let colors = RenderColor {
                own: args.color.map(resolve),
                inherited: color_given.map(resolve),
            };
            let cells = args.cells.map(|c| resolve_cells(c, env));
            run_render(&args, scene, &view, no_color, colors, cells).map(|()| 0)
        }
        Some(Command::Merge(a)) => tiles::run_merge(&a).map(|()| 0),
        Some(Command::Scenes) => stdout_is_open("the list").and_then(|()| {
            io::stdout()
                .write_all(crate::cli::scene_arg::list().as_bytes())
                .map(|()| 0)
                .map_err(Into::into)
        }),
        Some(Command::Bench(a)) => stdout_is_open("the table")
            .and_then(|()| run_bench(a, scene, &view))
            .map(|()| 0),
        None => run_default(
            color,
            resolve_cells(cli.cells, env),
            cli.graphics,
            scene,
            &view,
            dumb,
        ),
    };
    match result {
        Ok(code) => code,
        Err(Failure::Usage(message)) => {
            eprintln!("raytty: {}", without_os_error(&message));
            2
        }
        Err(Failure::Run(e)) if is_broken_pipe(&e) => 0,
        Err(Failure::Run(e)) => {
            eprintln!("raytty: {}", without_os_error(&format!("{e:#}")));
            1
        }
    }
}

/// The exit status of a run ended by signal `sig`: 128 + N, as shells report it. The app's
/// forced exit after a signal (when its loop cannot return in time) and a signal during a
/// model's load (`loading.rs`) use this too.
pub fn signal_status(sig: i32) -> u8 {
    (128 + sig).clamp(0, 255) as u8
}

/// The exit status of the app: 0 on quit, [`signal_status`] of the signal, and for a dropped
/// terminal that of SIGHUP (129), as if the hangup had been signalled.
#[cfg(feature = "tui")]
fn app_status(outcome: crate::tui::Outcome) -> u8 {
    use crate::tui::Outcome;
    match outcome {
        Outcome::Quit => 0,
        Outcome::Signal(sig) => signal_status(sig),
        Outcome::Hangup => signal_status(libc::SIGHUP),
    }
}

/// A failure if stdout was closed when raytty started (`>&-`): `what` would go nowhere.
fn stdout_is_open(what: &str) -> Result<()> {
    if render::stdout_was_closed() {
        return Err(anyhow::anyhow!(
            "stdout is closed: there is nowhere to write {what} (redirect it)"
        )
        .into());
    }
    Ok(())
}

/// `--scene` is a global flag, and clap checks a subcommand's `conflicts_with = "scene"` only
/// when `--scene` is given after the subcommand. This applies the same declarations (args.rs is
/// the one place that states them) when it comes before: `raytty --scene sphere bench --csv`.
fn global_conflicts(
    cmd: &mut clap::Command,
    matches: &clap::ArgMatches,
) -> std::result::Result<(), clap::Error> {
    use clap::parser::ValueSource::CommandLine;
    let Some((name, sub)) = matches.subcommand() else {
        return Ok(());
    };
    if matches.value_source("scene") != Some(CommandLine) {
        return Ok(());
    }
    let Some(sub_cmd) = cmd.find_subcommand_mut(name) else {
        return Ok(());
    };
    let given = sub_cmd.get_arguments().find(|arg| {
        sub.value_source(arg.get_id().as_str()) == Some(CommandLine)
            && sub_cmd
                .get_arg_conflicts_with(arg)
                .iter()
                .any(|c| c.get_id() == "scene")
    });
    match given {
        Some(arg) => {
            let flag = format!("--{}", arg.get_long().unwrap_or(arg.get_id().as_str()));
            Err(clap::Error::raw(
                clap::error::ErrorKind::ArgumentConflict,
                format!("the argument '{flag}' cannot be used with '--scene <PATH|NAME>'"),
            )
            .format(sub_cmd))
        }
        None => Ok(()),
    }
}

/// Why a command failed; its variant, and nothing else, picks the exit status in [`main`].
#[derive(Debug)]
pub enum Failure {
    /// What the user asked for is wrong or impossible, and the message says what would work:
    /// exit status 2 (clap's own usage errors are 2 as well).
    Usage(String),
    /// Running failed (I/O, a file that cannot be written): exit status 1, or 0 when the
    /// output pipe was closed by its reader.
    Run(anyhow::Error),
}

impl From<anyhow::Error> for Failure {
    fn from(e: anyhow::Error) -> Failure {
        Failure::Run(e)
    }
}

impl From<io::Error> for Failure {
    fn from(e: io::Error) -> Failure {
        Failure::Run(e.into())
    }
}

/// What the commands return.
pub type Result<T> = std::result::Result<T, Failure>;

/// Returns a [`Failure::Usage`] with a `format!` message.
macro_rules! usage {
    ($($arg:tt)*) => {
        return Err($crate::cli::Failure::Usage(format!($($arg)*)))
    };
}
pub(crate) use usage;

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<io::Error>()
            .is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe)
    })
}

/// Whether `TERM` names a terminal that cannot move its cursor (`dumb`, as in Emacs' shell):
/// the app cannot draw there, and auto colour means none.
fn is_dumb(term: Option<&str>) -> bool {
    term == Some("dumb")
}

/// No command: the app on a terminal; otherwise (or on a dumb terminal) one frame to stdout,
/// as `raytty render` with its defaults would print in `color`.
fn run_default(
    color: ColorMode,
    cells: raytty::frame::CellMode,
    graphics: GraphicsChoice,
    scene: Option<&str>,
    view: &raytty::scene::model::View,
    dumb: bool,
) -> Result<u8> {
    #[cfg(feature = "tui")]
    if io::stdout().is_terminal() {
        if !dumb {
            // A big scene takes seconds to generate and build: say so rather than show a
            // blank terminal, then erase the line before the app (or an error) takes over.
            let note = io::stderr().is_terminal();
            if note {
                eprint!(
                    "raytty: loading {}…",
                    raytty::printable(scene.unwrap_or("the Cornell box"))
                );
            }
            // The load's watch ends here: the app installs its own signal handlers.
            let loaded = crate::cli::scene_arg::load_scene(scene, view).map(|(s, _watch)| s);
            if note {
                eprint!("\r\x1b[2K");
            }
            use crate::tui::detect::{Choice, Protocol};
            let graphics = match graphics {
                GraphicsChoice::Auto => Choice::Auto,
                GraphicsChoice::Kitty => Choice::Force(Protocol::Kitty),
                GraphicsChoice::Sixel => Choice::Force(Protocol::Sixel),
                GraphicsChoice::None => Choice::None,
            };
            return Ok(crate::tui::run(loaded?, color, cells, graphics).map(app_status)?);
        }
        eprintln!("raytty: TERM=dumb cannot run the app (it moves the cursor): one frame follows");
    }
    #[cfg(not(feature = "tui"))]
    let _ = (dumb, cells, graphics);
    run_render(
        &RenderArgs {
            size: Some((80, 24)),
            pixels: None,
            format: Some(text_format(color)),
            color: None,
            cells: None,
            stage: Stage::Indirect,
            samples: None,
            sampler: None,
            denoise: Switch::On,
            camera: None,
            light: None,
            tonemap: None,
            output: None,
            tile: None,
            stats: None,
            simd: None,
            estimator: None,
        },
        scene,
        view,
        false,
        RenderColor::default(),
        None,
    )?;
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::render::{format_for, format_name, unwritable_image_extension};
    use super::*;

    #[test]
    fn output_extension_picks_the_format() {
        use std::path::Path;
        assert_eq!(format_for(Some(Path::new("a.png"))), Format::Png);
        assert_eq!(format_for(Some(Path::new("dir/A.PFM"))), Format::Pfm);
        assert_eq!(format_for(Some(Path::new("frame.txt"))), Format::Ansi);
        assert_eq!(format_for(None), Format::Ansi);
        assert_eq!(
            unwritable_image_extension(Path::new("box.JPG")).as_deref(),
            Some("jpg")
        );
        assert_eq!(unwritable_image_extension(Path::new("box.png")), None);
        assert_eq!(unwritable_image_extension(Path::new("frame.txt")), None);
        assert_eq!(unwritable_image_extension(Path::new("frame")), None);
        assert_eq!(format_name(Format::Png), "png");
    }

    #[test]
    fn os_error_numbers_are_dropped_from_messages() {
        assert_eq!(
            without_os_error("cannot create x: No such file or directory (os error 2)"),
            "cannot create x: No such file or directory"
        );
        assert_eq!(without_os_error("a (os error 2); b (os error 28)"), "a; b");
        assert_eq!(without_os_error("kept (os error x)"), "kept (os error x)");
    }

    #[test]
    fn a_dumb_terminal_is_recognised() {
        assert!(is_dumb(Some("dumb")));
        assert!(!is_dumb(Some("xterm-256color")));
        assert!(!is_dumb(Some("")));
        assert!(!is_dumb(None));
    }

    #[test]
    fn auto_colour_follows_no_color_then_colorterm() {
        let auto = ColorChoice::Auto;
        assert_eq!(
            resolve_color(auto, true, Some("truecolor")),
            ColorMode::Ascii
        );
        assert_eq!(
            resolve_color(auto, false, Some("truecolor")),
            ColorMode::TrueColor
        );
        assert_eq!(
            resolve_color(auto, false, Some("24bit")),
            ColorMode::TrueColor
        );
        assert_eq!(resolve_color(auto, false, Some("yes")), ColorMode::Ansi256);
        assert_eq!(resolve_color(auto, false, None), ColorMode::Ansi256);
        assert_eq!(
            resolve_color(ColorChoice::Truecolor, true, None),
            ColorMode::TrueColor
        );
    }
}
