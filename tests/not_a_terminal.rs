//! With stdout not a terminal, `raytty` with no command prints one frame and exits 0: no raw
//! mode, no alternate screen. `--color` and NO_COLOR pick the frame's colours.

use std::process::{Command, Output, Stdio};

fn raytty(args: &[&str], no_color: bool, colorterm: Option<&str>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_raytty"));
    cmd.args(args).stdin(Stdio::null()).env_remove("NO_COLOR");
    if no_color {
        cmd.env("NO_COLOR", "1");
    }
    match colorterm {
        Some(v) => cmd.env("COLORTERM", v),
        None => cmd.env_remove("COLORTERM"),
    };
    cmd.output().expect("run raytty")
}

#[test]
fn a_pipe_gets_one_frame_in_the_chosen_colours() {
    for (args, no_color, colorterm, sgr) in [
        (&[][..], false, Some("truecolor"), Some("38;2;")),
        (&[][..], false, None, Some("38;5;")),
        (&[][..], true, Some("24bit"), None),
        (&["--color", "truecolor"][..], true, None, Some("38;2;")),
        (&["--color", "ascii"][..], false, Some("truecolor"), None),
    ] {
        let out = raytty(args, no_color, colorterm);
        assert!(out.status.success(), "{args:?}");
        let text = String::from_utf8(out.stdout).expect("utf-8");
        assert_eq!(text.lines().count(), 24, "{args:?}");
        assert!(
            !text.contains("\x1b[?1049h"),
            "entered the alternate screen"
        );
        match sgr {
            Some(s) => assert!(text.contains(s), "{args:?} {no_color} {colorterm:?}"),
            None => assert!(!text.contains('\x1b'), "{args:?} {no_color} {colorterm:?}"),
        }
    }
}
