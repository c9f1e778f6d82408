//! MTL, OBJ's material libraries: `newmtl`, `Kd`, `Ks`, `Ns`, `Ke`, `Ni`, `d` (or `Tr`),
//! `illum`, `map_Kd`, and the physically based extension's `Pr` (roughness) and `Pm`
//! (metallic). Other statements are ignored. Errors name the line and column.

use glam::Vec3;

use super::ModelMaterial;
use crate::scene::obj::ObjError;

/// The same tokenizer as OBJ: whitespace-separated, with 1-based byte columns.
fn tokens(line: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    line.split(|b| b.is_ascii_whitespace())
        .scan(1usize, |at, tok| {
            let start = *at;
            *at += tok.len() + 1;
            Some((start, tok))
        })
        .filter(|(_, t)| !t.is_empty())
}

/// Reads `bytes` as an MTL library: its materials, each with the MTL values mapped onto the
/// physically based parameters. Colours are taken as linear (MTL has no colour space).
pub fn parse_mtl(bytes: &[u8]) -> Result<Vec<ModelMaterial>, ObjError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut out: Vec<ModelMaterial> = Vec::new();
    // Values only the end of a material can combine: Ns and Ks (roughness when no Pr).
    let mut shininess: Vec<Option<f32>> = Vec::new();
    let mut has_roughness: Vec<bool> = Vec::new();
    for (n, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = n + 1;
        let content = match raw.iter().position(|&b| b == b'#') {
            Some(i) => &raw[..i],
            None => raw,
        };
        let mut toks = tokens(content);
        let Some((col, keyword)) = toks.next() else {
            continue;
        };
        let err = |byte_column: usize, message: String| {
            let before = &raw[..byte_column.saturating_sub(1).min(raw.len())];
            ObjError {
                line,
                column: String::from_utf8_lossy(before).chars().count() + 1,
                message,
            }
        };
        let key = String::from_utf8_lossy(keyword);
        if keyword == b"newmtl" {
            let Some((c, _)) = toks.next() else {
                return Err(err(col, "`newmtl` needs a name".into()));
            };
            out.push(ModelMaterial {
                name: String::from_utf8_lossy(&content[c - 1..])
                    .trim()
                    .to_string(),
                ..ModelMaterial::default()
            });
            shininess.push(None);
            has_roughness.push(false);
            continue;
        }
        let known = [
            &b"Kd"[..],
            b"Ks",
            b"Ns",
            b"Ke",
            b"Ni",
            b"d",
            b"Tr",
            b"illum",
            b"map_Kd",
            b"Pr",
            b"Pm",
        ];
        if !known.contains(&keyword) {
            continue;
        }
        let i = out.len().wrapping_sub(1);
        let Some(m) = out.last_mut() else {
            return Err(err(
                col,
                format!("`{key}` before any `newmtl NAME`: a value belongs to a material"),
            ));
        };
        if keyword == b"map_Kd" {
            // Options (`-o 1 1`, `-s ...`) come first; the file name is the last token.
            let Some((_, name)) = toks.last() else {
                return Err(err(col, "`map_Kd` needs a texture file name".into()));
            };
            m.base_colour_texture = Some(String::from_utf8_lossy(name).into_owned());
            continue;
        }
        let count = match keyword {
            b"Kd" | b"Ks" | b"Ke" => 3,
            _ => 1,
        };
        let mut v = [0.0f32; 3];
        for i in 0..count {
            let Some((c, tok)) = toks.next() else {
                if i == 1 {
                    // `Kd 0.5` is a grey.
                    v = [v[0]; 3];
                    break;
                }
                return Err(err(
                    col,
                    format!("`{key}` needs {count} number(s), this one has {i}"),
                ));
            };
            if i == 0 && (tok == b"spectral" || tok == b"xyz") {
                return Err(err(
                    c,
                    format!(
                        "`{key} {}`: only RGB values are read (`{key} r g b`)",
                        String::from_utf8_lossy(tok)
                    ),
                ));
            }
            let x = std::str::from_utf8(tok)
                .ok()
                .and_then(|s| s.parse::<f32>().ok())
                .filter(|x| x.is_finite() && *x >= 0.0)
                .ok_or_else(|| {
                    err(
                        c,
                        format!(
                            "`{}` is not a finite non-negative number (`{key}` wants one)",
                            String::from_utf8_lossy(tok)
                        ),
                    )
                })?;
            let max = match keyword {
                b"Ns" => 1e4,
                b"Ni" => 10.0,
                b"illum" => 10.0,
                b"Ke" => 1e6,
                _ => 1.0,
            };
            if x > max {
                return Err(err(
                    c,
                    format!("`{key}` {x} is out of range: expected 0 to {max}"),
                ));
            }
            v[i] = x;
        }
        match keyword {
            b"Kd" => m.base_colour = Vec3::from(v),
            b"Ke" => m.emission = Vec3::from(v),
            b"Ks" => {}
            b"Ns" => shininess[i] = Some(v[0]),
            b"Ni" => m.ior = v[0].max(1.0),
            b"d" => m.opacity = v[0],
            b"Tr" => m.opacity = 1.0 - v[0],
            b"Pr" => {
                m.roughness = v[0];
                has_roughness[i] = true;
            }
            b"Pm" => m.metallic = v[0],
            // illum 4, 6, 7, 9: glass; the transmitted part is what the opacity leaves.
            b"illum" => {
                if matches!(v[0] as u32, 4 | 6 | 7 | 9) {
                    m.transmission = 1.0;
                }
            }
            _ => {}
        }
    }
    for (i, m) in out.iter_mut().enumerate() {
        if !has_roughness[i] {
            // Phong exponent to roughness (the Blinn-Phong / Beckmann match α² = 2 / (Ns + 2),
            // perceptual roughness = √α); no Ns: a matte surface.
            m.roughness = shininess[i].map_or(1.0, |ns| (2.0 / (ns + 2.0)).powf(0.25));
        }
        if m.transmission > 0.0 {
            m.transmission = 1.0 - m.opacity.min(1.0);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_map_onto_the_material() {
        let m = parse_mtl(
            b"# lib\nnewmtl red paint\nKd 0.8 0.1 0.1\nKs 0.5 0.5 0.5\nNs 98\nKe 0 0 0\nNi 1.45\nd 1\nillum 2\nmap_Kd -s 1 1 1 red.png\nnewmtl metal\nKd 0.5\nPr 0.2\nPm 1\n",
        )
        .unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m[0].name, "red paint");
        assert_eq!(m[0].base_colour, Vec3::new(0.8, 0.1, 0.1));
        assert_eq!(m[0].ior, 1.45);
        assert_eq!(m[0].base_colour_texture.as_deref(), Some("red.png"));
        assert!((m[0].roughness - (2.0f32 / 100.0).powf(0.25)).abs() < 1e-6);
        assert_eq!(m[1].base_colour, Vec3::splat(0.5));
        assert_eq!((m[1].roughness, m[1].metallic), (0.2, 1.0));
    }

    #[test]
    fn mistakes_name_line_and_column() {
        let e = parse_mtl(b"newmtl a\nKd 0.5 x 1\n").unwrap_err();
        assert_eq!((e.line, e.column), (2, 8), "{}", e.message);
        let e = parse_mtl(b"Kd 1 1 1\n").unwrap_err();
        assert!(e.message.contains("newmtl"), "{}", e.message);
        let e = parse_mtl(b"newmtl a\nKd 2 0 0\n").unwrap_err();
        assert!(e.message.contains("out of range"), "{}", e.message);
        let e = parse_mtl(b"newmtl a\nd -1\n").unwrap_err();
        assert_eq!((e.line, e.column), (2, 3));
        let e = parse_mtl(b"newmtl a\nKd spectral x.spd\n").unwrap_err();
        assert!(e.message.contains("RGB"), "{}", e.message);
    }
}
