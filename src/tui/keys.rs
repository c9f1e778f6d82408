//! The keys: a pure mapping from a key event to a [`Message`], and the table the help overlay
//! and `--help` show. The seed's keys come first and keep their meaning.

use crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};
use glam::Vec3;
use raytty::Stage;

use super::app::Message;

/// One press of ↑/↓ moves the camera this far (scene units; the Cornell box is 2 wide).
pub const WALK_STEP: f32 = 0.1;
/// One press of ←/→ turns the camera this many degrees.
pub const TURN_STEP_DEGREES: f32 = 5.0;
/// One press of W/A/S/D/Q/E moves the light this far (scene units).
pub const LIGHT_STEP: f32 = 0.1;
/// One press of - widens the field of view by this factor; + narrows it by as much.
pub const ZOOM_STEP: f32 = 1.15;
/// With Shift, every step is this fraction of the normal one.
pub const FINE: f32 = 0.2;

/// The keys as the help overlay lists them: (keys, what they do).
pub const KEYS: &[(&str, &str)] = &[
    ("Up / Down", "move forward / back (Shift: finer)"),
    ("Left / Right", "turn left / right (Shift: finer)"),
    ("PgUp / PgDn", "look up / down (Shift: finer)"),
    ("+ / -", "zoom in / out"),
    ("F", "frame the model again (the starting view)"),
    (
        "Mouse",
        "drag: orbit; wheel: zoom (Shift+drag selects text)",
    ),
    ("W / S", "light forward / back (Shift: finer)"),
    ("A / D", "light left / right (Shift: finer)"),
    ("Q / E", "light up / down (Shift: finer)"),
    ("1-6", "stage: flat light direct shadows indirect gi"),
    ("N", "gi: denoiser on / off (off: raw, unbiased)"),
    ("R", "reset camera and light"),
    ("C", "colour mode: truecolor 256 ascii"),
    ("B", "cells: half quadrant sextant octant"),
    ("G", "pixels (kitty or sixel) on / off"),
    ("H or ?", "this help"),
    ("Ctrl-Z", "suspend (fg resumes)"),
    ("Esc, Ctrl-C", "quit"),
];

/// The keys as `--help` lists them after the options.
pub fn help_text() -> String {
    let mut s = String::from("Keys in the app:\n");
    for (k, what) in KEYS {
        s.push_str(&format!("  {k:<13} {what}\n"));
    }
    s
}

/// One cell of mouse drag orbits the camera this many degrees.
pub const ORBIT_DEGREES_PER_CELL: f32 = 2.0;

/// The message for a mouse event: a drag orbits, the wheel zooms (up: in).
pub fn message_for_mouse(m: super::input::Mouse) -> Option<Message> {
    use super::input::Mouse;
    let step = ORBIT_DEGREES_PER_CELL.to_radians();
    match m {
        Mouse::Drag(0, 0) | Mouse::Wheel(0) => None,
        Mouse::Drag(dx, dy) => Some(Message::Orbit(dx as f32 * step, dy as f32 * step)),
        Mouse::Wheel(n) => Some(Message::Zoom(ZOOM_STEP.powi(n))),
    }
}

/// The message for a key, if it has one. Acts on presses and repeats, never on releases (the
/// kitty protocol and Windows report both). Upper-case light keys (Shift) take fine steps.
pub fn message_for(key: KeyEvent) -> Option<Message> {
    if !matches!(key.kind, KeyEventKind::Press | KeyEventKind::Repeat) {
        return None;
    }
    let fine = |shift: bool| if shift { FINE } else { 1.0 };
    let shift = key.modifiers.contains(KeyModifiers::SHIFT);
    let turn = TURN_STEP_DEGREES.to_radians() * fine(shift);
    let walk = WALK_STEP * fine(shift);
    match key.code {
        KeyCode::Esc => Some(Message::Quit),
        KeyCode::Char('c' | 'C') if key.modifiers.contains(KeyModifiers::CONTROL) => {
            Some(Message::Quit)
        }
        KeyCode::Char('z' | 'Z') if key.modifiers.contains(KeyModifiers::CONTROL) => {
            Some(Message::Suspend)
        }
        KeyCode::Up => Some(Message::Walk(walk)),
        KeyCode::Down => Some(Message::Walk(-walk)),
        KeyCode::Left => Some(Message::Turn(-turn)),
        KeyCode::Right => Some(Message::Turn(turn)),
        KeyCode::PageUp => Some(Message::Pitch(-turn)),
        KeyCode::PageDown => Some(Message::Pitch(turn)),
        KeyCode::Char(c) => {
            let step = LIGHT_STEP * fine(c.is_ascii_uppercase() || shift);
            let light =
                |x: f32, y: f32, z: f32| Some(Message::MoveLight(Vec3::new(x, y, z) * step));
            match c.to_ascii_lowercase() {
                'w' => light(0.0, 0.0, 1.0),
                's' => light(0.0, 0.0, -1.0),
                'a' => light(-1.0, 0.0, 0.0),
                'd' => light(1.0, 0.0, 0.0),
                // y points down: up is −y.
                'q' => light(0.0, -1.0, 0.0),
                'e' => light(0.0, 1.0, 0.0),
                'r' => Some(Message::Reset),
                'f' => Some(Message::Frame),
                '+' | '=' => Some(Message::Zoom(1.0 / ZOOM_STEP)),
                '-' | '_' => Some(Message::Zoom(ZOOM_STEP)),
                'n' => Some(Message::ToggleDenoise),
                'c' => Some(Message::CycleColor),
                'b' => Some(Message::CycleCells),
                'g' => Some(Message::ToggleGraphics),
                'h' | '?' => Some(Message::ToggleHelp),
                d @ '1'..='9' => Stage::ALL
                    .get(d as usize - '1' as usize)
                    .map(|&s| Message::SetStage(s)),
                _ => None,
            }
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(code: KeyCode, modifiers: KeyModifiers) -> KeyEvent {
        KeyEvent::new(code, modifiers)
    }

    fn press(c: char) -> Option<Message> {
        message_for(key(KeyCode::Char(c), KeyModifiers::NONE))
    }

    #[test]
    fn the_seed_keys_keep_their_meaning() {
        let none = KeyModifiers::NONE;
        assert_eq!(
            message_for(key(KeyCode::Up, none)),
            Some(Message::Walk(WALK_STEP))
        );
        assert_eq!(
            message_for(key(KeyCode::Down, none)),
            Some(Message::Walk(-WALK_STEP))
        );
        assert_eq!(
            message_for(key(KeyCode::Left, none)),
            Some(Message::Turn(-TURN_STEP_DEGREES.to_radians()))
        );
        assert_eq!(
            press('q'),
            Some(Message::MoveLight(Vec3::new(0.0, -LIGHT_STEP, 0.0)))
        );
        assert_eq!(
            press('d'),
            Some(Message::MoveLight(Vec3::new(LIGHT_STEP, 0.0, 0.0)))
        );
        assert_eq!(
            press('s'),
            Some(Message::MoveLight(Vec3::new(0.0, 0.0, -LIGHT_STEP)))
        );
    }

    #[test]
    fn shift_gives_finer_steps() {
        assert_eq!(
            message_for(key(KeyCode::Right, KeyModifiers::SHIFT)),
            Some(Message::Turn(TURN_STEP_DEGREES.to_radians() * FINE))
        );
        assert_eq!(
            message_for(key(KeyCode::Char('W'), KeyModifiers::SHIFT)),
            Some(Message::MoveLight(Vec3::new(0.0, 0.0, LIGHT_STEP * FINE)))
        );
    }

    #[test]
    fn stages_reset_colour_help_and_quit() {
        for (i, &s) in Stage::ALL.iter().enumerate() {
            assert_eq!(
                press(char::from(b'1' + i as u8)),
                Some(Message::SetStage(s))
            );
        }
        assert_eq!(press('0'), None);
        assert_eq!(press('9'), None);
        assert_eq!(press('R'), Some(Message::Reset));
        assert_eq!(press('n'), Some(Message::ToggleDenoise));
        assert_eq!(press('c'), Some(Message::CycleColor));
        assert_eq!(press('?'), Some(Message::ToggleHelp));
        assert_eq!(press('h'), Some(Message::ToggleHelp));
        assert_eq!(
            message_for(key(KeyCode::Esc, KeyModifiers::NONE)),
            Some(Message::Quit)
        );
        assert_eq!(
            message_for(key(KeyCode::Char('c'), KeyModifiers::CONTROL)),
            Some(Message::Quit)
        );
        assert_eq!(press('x'), None);
    }

    #[test]
    fn releases_are_ignored_and_repeats_act() {
        let mut k = key(KeyCode::Up, KeyModifiers::NONE);
        k.kind = KeyEventKind::Release;
        assert_eq!(message_for(k), None);
        k.kind = KeyEventKind::Repeat;
        assert_eq!(message_for(k), Some(Message::Walk(WALK_STEP)));
    }
}
