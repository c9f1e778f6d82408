//! Text from outside (a scene's name, a path, a key from a scene file) made safe to show in a
//! terminal. The bottom layer: scene file errors and the app's status line use it.

/// `s` without control characters (C0, DEL, C1) or format characters (bidi overrides and
/// isolates, zero-width joiners and spaces, the BOM, ...): safe to show in a terminal, and shown
/// left to right as it is stored. Text from outside (a scene's name, a path, a key from a scene
/// file) goes through this before it is shown.
pub fn printable(s: &str) -> String {
    s.chars()
        .filter(|&c| !c.is_control() && !is_format(c))
        .collect()
}

/// Unicode's format characters (general category Cf), which change how the text around them is
/// laid out without showing anything themselves.
fn is_format(c: char) -> bool {
    matches!(
        c as u32,
        0xAD | 0x600..=0x605
            | 0x61C
            | 0x6DD
            | 0x70F
            | 0x890..=0x891
            | 0x8E2
            | 0x180E
            | 0x200B..=0x200F
            | 0x202A..=0x202E
            | 0x2060..=0x2064
            | 0x2066..=0x206F
            | 0xFEFF
            | 0xFFF9..=0xFFFB
            | 0x110BD
            | 0x110CD
            | 0x13430..=0x1343F
            | 0x1BCA0..=0x1BCA3
            | 0x1D173..=0x1D17A
            | 0xE0001
            | 0xE0020..=0xE007F
    )
}
