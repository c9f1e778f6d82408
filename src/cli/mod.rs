//! Command-line parsing and the non-interactive commands. The exit code is chosen here, once:
//! 0 for success (a closed output pipe included), 1 for a failure while running, 2 for bad
//! input (clap's own usage errors are 2 as well).

mod args;
mod bench;
mod render;
pub mod scene_arg;

use std::io::{self, IsTerminal, Write};
use std::process::ExitCode;

use anyhow::Result;
use clap::{CommandFactory, FromArgMatches};
use raytty::{ColorMode, Stage};

use args::*;
use bench::run_bench;
use render::{run_render, without_os_error};

/// Parses the command line, runs it, and maps the outcome to an exit code.
pub fn main() -> ExitCode {
    #[allow(unused_mut)]
    let mut cmd = Cli::command();
    #[cfg(feature = "tui")]
    {
        cmd = cmd.after_long_help(crate::tui::keys::help_text());
    }
    let cli = Cli::from_arg_matches(&cmd.get_matches()).unwrap_or_else(|e| e.exit());
    let dumb = is_dumb(std::env::var("TERM").ok().as_deref());
    let no_color = std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty());
    let color = resolve_color(
        cli.color,
        dumb || no_color,
        std::env::var("COLORTERM").ok().as_deref(),
    );
    let result = match cli.command {
        Some(Command::Render(args)) => {
            run_render(&args, cli.scene.as_deref(), no_color).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::Scenes) => io::stdout()
            .write_all(crate::cli::scene_arg::list().as_bytes())
            .map(|()| ExitCode::SUCCESS)
            .map_err(Into::into),
        Some(Command::Bench(a)) => run_bench(a, cli.scene.as_deref()).map(|()| ExitCode::SUCCESS),
        None => run_default(color, cli.scene.as_deref(), dumb),
    };
    match result {
        Ok(code) => code,
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("raytty: {}", without_os_error(&format!("{e:#}")));
            ExitCode::from(if e.downcast_ref::<UsageError>().is_some() {
                2
            } else {
                1
            })
        }
    }
}

/// An error in what the user asked for (exit status 2).
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

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
fn run_default(color: ColorMode, scene: Option<&str>, dumb: bool) -> Result<ExitCode> {
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
            let loaded = crate::cli::scene_arg::load_scene(scene);
            if note {
                eprint!("\r\x1b[2K");
            }
            return crate::tui::run(loaded?, color);
        }
        eprintln!("raytty: TERM=dumb cannot run the app (it moves the cursor): one frame follows");
    }
    #[cfg(not(feature = "tui"))]
    let _ = dumb;
    run_render(
        &RenderArgs {
            size: Some((80, 24)),
            pixels: None,
            format: Some(match color {
                ColorMode::TrueColor => Format::Ansi,
                ColorMode::Ansi256 => Format::Ansi256,
                ColorMode::Ascii => Format::Ascii,
            }),
            stage: Stage::Indirect,
            samples: None,
            camera: None,
            light: None,
            output: None,
            stats: None,
        },
        scene,
        false,
    )?;
    Ok(ExitCode::SUCCESS)
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
