//! The MTL reader: `newmtl` blocks with their `Kd`, `Ke` and `map_Kd`,
//! each value with its position for messages, the statements that make a
//! material more than diffuse (noted for one warning per file), and the
//! average colour of `map_Kd` textures. The module docs of the OBJ reader
//! say how a block becomes a [`Material`].

use super::scan::{lines, words};
use super::ReadTexture;
use super::{name_list, Tally, DEFAULT_REFLECTANCE, DIFFUSE_SHEEN_LIMIT, MAX_MTL_REFLECTANCE};
use crate::budget::MemoryBudget;
use crate::color::Rgb;
use crate::scene::error::{fmt_num, negative_channel};
use crate::scene::import::sc::MAX_EMISSION;
use crate::scene::import::texture;
use crate::scene::{Diagnostic, Material, SourcePos, Warning};
use std::path::Path;

/// One material library as read.
pub(super) struct Library {
    pub(super) file: String,
    /// The OBJ line of the `mtllib` that loaded it.
    pub(super) loaded_at: u32,
    pub(super) materials: Vec<MtlMaterial>,
    pub(super) diags: Vec<Diagnostic>,
    pub(super) warnings: Vec<Warning>,
    /// `map_Kd` paths written with `\`: how many, and the first.
    pub(super) backslashes: Tally,
}

/// One `newmtl` block: the values that matter here, with positions.
pub(super) struct MtlMaterial {
    pub(super) name: String,
    pub(super) file: String,
    pub(super) pos: SourcePos,
    /// `Kd` as used (clamped below one), `None` when the block has none.
    pub(super) kd: Option<Rgb>,
    /// `Kd` as written (a model's base colour, which may reach one).
    pub(super) kd_written: Option<Rgb>,
    pub(super) ke: Rgb,
    /// The `map_Kd` file (with `/` for `\`) and where it is named.
    pub(super) map_kd: Option<(String, SourcePos)>,
    /// The options written before the `map_Kd` file, word by word
    /// (`-s 2 2 1 -clamp on`).
    pub(super) map_kd_options: Vec<String>,
    /// The average linear colour of the `map_Kd` texture, once read.
    pub(super) texture: Option<Rgb>,
    /// Statements asking for more than diffuse reflection, as written
    /// (`Ks 0.5`, `illum 7`, ...).
    pub(super) non_diffuse: Vec<String>,
    /// `illum` and `Ni` are only known together at the end of the block.
    pub(super) illum: Option<i64>,
    pub(super) ni: Option<f64>,
}

impl MtlMaterial {
    /// The diffuse reflectance used: `Kd` (or [`DEFAULT_REFLECTANCE`]),
    /// times the average of the `map_Kd` texture when it was read.
    pub(super) fn reflectance(&self) -> Rgb {
        let kd = self.kd.unwrap_or(Rgb::splat(DEFAULT_REFLECTANCE));
        match self.texture {
            Some(t) => kd * t,
            None => kd,
        }
    }

    /// The scene material: see the module docs for the mapping.
    pub(super) fn to_material(&self) -> Material {
        let kd = self.reflectance();
        let (color, k_diffrefl, k_emission) = if self.ke.is_black() {
            (kd, 1.0, 0.0)
        } else if kd.is_black() {
            (self.ke, 0.0, 1.0)
        } else {
            let lum = |c: Rgb| c.luminance().max(f64::MIN_POSITIVE);
            let k = lum(kd) / lum(self.ke);
            // Below one in every channel, like Kd itself.
            let k = k.min(kd.max_channel() / self.ke.max_channel());
            (self.ke, k, 1.0)
        };
        Material {
            name: self.name.clone(),
            color,
            k_diffrefl,
            k_emission,
        }
    }

    /// Notes what the block's `illum` and `Ni` ask for, once it is read.
    pub(super) fn finish(&mut self) {
        if let Some(illum) = self.illum.filter(|i| (3..=9).contains(i)) {
            self.non_diffuse.push(format!("illum {illum}"));
            if let Some(ni) = self.ni.filter(|_| matches!(illum, 4 | 6 | 7)) {
                self.non_diffuse.push(format!("Ni {}", fmt_num(ni)));
            }
        }
    }
}

/// The first number after the keyword, if it is one (MTL statements this
/// module only warns about are never errors).
pub(super) fn number(w: &[(&str, u32)]) -> Option<f64> {
    w.get(1)
        .and_then(|(x, _)| x.parse::<f64>().ok())
        .filter(|x| x.is_finite())
}

/// A `map_Kd` line split into its options (every word between the
/// keyword and the file: `-s 1 1 1`, `-bm 0.5`, ...) and its file, the
/// rest of the line, so that names with spaces are kept.
pub(super) fn map_parts<'a>(
    line: &'a str,
    w: &[(&'a str, u32)],
) -> Option<(Vec<&'a str>, &'a str)> {
    let mut i = 1;
    while let Some(&(word, _)) = w.get(i) {
        let args = match word {
            "-o" | "-s" | "-t" => 3,
            "-mm" => 2,
            "-blendu" | "-blendv" | "-bm" | "-boost" | "-cc" | "-clamp" | "-imfchan"
            | "-texres" | "-type" => 1,
            _ => break,
        };
        i += 1;
        // `-o`, `-s` and `-t` take one to three numbers.
        for _ in 0..args {
            match w.get(i) {
                Some((x, _)) if args < 3 || x.parse::<f64>().is_ok() => i += 1,
                _ => break,
            }
        }
    }
    let &(_, col) = w.get(i)?;
    let start = line.char_indices().nth(col as usize - 1)?.0;
    let options = w[1..i].iter().map(|(x, _)| *x).collect();
    Some((options, line[start..].trim()))
}

/// Reads an MTL library: `newmtl`, `Kd`, `Ke` and `map_Kd`, and notes the
/// statements of non-diffuse materials (see the module docs). `loaded_at`
/// is the OBJ line that names it.
pub(super) fn parse_mtl(text: &str, file: &str, loaded_at: u32) -> Library {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lib = Library {
        file: file.to_string(),
        loaded_at,
        materials: Vec::new(),
        diags: Vec::new(),
        warnings: Vec::new(),
        backslashes: Tally::default(),
    };
    for (number_, line) in lines(text) {
        let w = words(line);
        let Some(&(keyword, col)) = w.first() else {
            continue;
        };
        let at = |col: u32| SourcePos { line: number_, col };
        if keyword == "newmtl" {
            start_material(&mut lib, file, line, at(col));
            continue;
        }
        let Some(m) = lib.materials.last_mut() else {
            if matches!(keyword, "Kd" | "Ke") {
                lib.diags.push(Diagnostic::new(
                    file,
                    at(col),
                    format!("`{keyword}` before any `newmtl`"),
                ));
            }
            continue;
        };
        match keyword {
            "Kd" | "Ke" => set_color(&mut lib.diags, &mut lib.warnings, m, &w, file, number_),
            "map_Kd" => {
                if let Some((options, name)) = map_parts(line, &w).filter(|p| !p.1.is_empty()) {
                    m.map_kd_options = options.into_iter().map(str::to_string).collect();
                    let path = if name.contains('\\') {
                        lib.backslashes.add(at(col), || name.to_string());
                        name.replace('\\', "/")
                    } else {
                        name.to_string()
                    };
                    m.map_kd = Some((path, at(col)));
                }
            }
            "Ks" => {
                if let Ok(ks) = color(&w) {
                    if ks.max_channel() > DIFFUSE_SHEEN_LIMIT {
                        m.non_diffuse
                            .push(format!("Ks {}", fmt_num(ks.max_channel())));
                    }
                }
            }
            "illum" => m.illum = w.get(1).and_then(|(x, _)| x.parse().ok()),
            "Ni" => m.ni = number(&w),
            "d" => {
                if let Some(d) = number(&w).filter(|&d| d < 1.0) {
                    m.non_diffuse.push(format!("d {}", fmt_num(d)));
                }
            }
            "Tr" => {
                if let Some(tr) = number(&w).filter(|&t| t > 0.0) {
                    m.non_diffuse.push(format!("Tr {}", fmt_num(tr)));
                }
            }
            "Pm" => {
                if let Some(pm) = number(&w).filter(|&p| p > 0.0) {
                    m.non_diffuse.push(format!("Pm {}", fmt_num(pm)));
                }
            }
            "Pr" => {
                if let Some(pr) = number(&w).filter(|&p| p < DIFFUSE_SHEEN_LIMIT) {
                    m.non_diffuse.push(format!("Pr {}", fmt_num(pr)));
                }
            }
            _ => {}
        }
    }
    if let Some(m) = lib.materials.last_mut() {
        m.finish();
    }
    warn_about_materials(&mut lib);
    lib
}

/// Starts the block of a `newmtl` line of `file` at `pos` (the name is everything
/// after the keyword, trimmed, as `tobj` reads it), finishing the one
/// before; a `newmtl` without a name is an error.
fn start_material(lib: &mut Library, file: &str, line: &str, pos: SourcePos) {
    // As tobj reads it: everything after the keyword, trimmed.
    let name = line.trim_start()["newmtl".len()..].trim();
    if name.is_empty() {
        lib.diags
            .push(Diagnostic::new(file, pos, "`newmtl` needs a material name"));
        return;
    }
    if let Some(m) = lib.materials.last_mut() {
        m.finish();
    }
    lib.materials.push(MtlMaterial {
        name: name.to_string(),
        file: file.to_string(),
        pos,
        kd: None,
        kd_written: None,
        ke: Rgb::BLACK,
        map_kd: None,
        map_kd_options: Vec::new(),
        texture: None,
        non_diffuse: Vec::new(),
        illum: None,
        ni: None,
    });
}

/// Sets `Kd` or `Ke` (as `w` says) of material `m` from a line of `file`
/// (line `number_`): a `Kd` at or above one is scaled below one with a
/// warning; a bad colour is an error.
fn set_color(
    diags: &mut Vec<Diagnostic>,
    warnings: &mut Vec<Warning>,
    m: &mut MtlMaterial,
    w: &[(&str, u32)],
    file: &str,
    number_: u32,
) {
    let (keyword, col) = w[0];
    let at = |col: u32| SourcePos { line: number_, col };
    match color(w) {
        Err((c, message)) => diags.push(Diagnostic::new(file, at(c), message)),
        Ok(rgb) if keyword == "Ke" && rgb.max_channel() > MAX_EMISSION => {
            // The `.sc` format's limit: emission × area summed over the
            // scene stays finite, and so do the pictures' f32 values.
            let (word, c) = w[1..]
                .iter()
                .copied()
                .find(|(x, _)| x.parse::<f64>().is_ok_and(|x| x > MAX_EMISSION))
                .unwrap_or(w[0]);
            diags.push(Diagnostic::new(
                file,
                at(c),
                format!(
                    "`Ke` channel {word} is too large; emission must be at most {} per channel",
                    fmt_num(MAX_EMISSION)
                ),
            ));
        }
        Ok(rgb) if keyword == "Ke" => m.ke = rgb,
        Ok(rgb) if keyword == "Kd" && rgb.max_channel() >= 1.0 => {
            m.kd_written = Some(rgb);
            // Same hue, brightest channel at the cap.
            let clamped = rgb * (MAX_MTL_REFLECTANCE / rgb.max_channel());
            let show = |c: Rgb| c.to_array().map(fmt_num).join(" ");
            warnings.push(Warning::at(
                file,
                at(col),
                format!(
                    "material `{}`: `Kd {}` reflects all light or more; scaled to {} (brightest channel {})",
                    m.name,
                    show(rgb),
                    show(clamped),
                    fmt_num(MAX_MTL_REFLECTANCE)
                ),
            ));
            m.kd = Some(clamped);
        }
        Ok(rgb) => {
            m.kd_written = Some(rgb);
            m.kd = Some(rgb);
        }
    }
}

/// The warnings about a whole library: its materials without `Kd`, and
/// those treated as diffuse though they ask for more.
fn warn_about_materials(lib: &mut Library) {
    let file = lib.file.as_str();
    let no_kd: Vec<String> = lib
        .materials
        .iter()
        .filter(|m| m.kd.is_none())
        .map(|m| m.name.clone())
        .collect();
    if !no_kd.is_empty() {
        lib.warnings.push(Warning::file(
            file,
            format!(
                "no `Kd` in {}: reflectance {} (the default)",
                name_list(&no_kd),
                fmt_num(DEFAULT_REFLECTANCE)
            ),
        ));
    }
    let shiny: Vec<String> = lib
        .materials
        .iter()
        .filter(|m| !m.non_diffuse.is_empty())
        .map(|m| format!("{} ({})", m.name, m.non_diffuse.join(", ")))
        .collect();
    if !shiny.is_empty() {
        lib.warnings.push(Warning::file(
            file,
            format!("treated as diffuse: {}", name_list(&shiny)),
        ));
    }
}

/// Reads each `map_Kd` texture of `lib` (relative to the library's folder)
/// and records its average colour; one warning for those that cannot be
/// read (they keep their `Kd`), one for paths written with `\`. A texture
/// is read through `read` (the input rules) and decoded within `budget`
/// ([`texture`]).
pub(super) fn read_textures(lib: &mut Library, read: &ReadTexture<'_>, budget: &MemoryBudget) {
    let dir = Path::new(&lib.file)
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let mut failed = Tally::default();
    for m in &mut lib.materials {
        let Some((name, pos)) = &m.map_kd else {
            continue;
        };
        let path = dir.join(name);
        match read(&path).and_then(|bytes| {
            texture::average_bytes(&bytes, image::ImageFormat::from_path(&path).ok(), budget)
        }) {
            Ok(rgb) => m.texture = Some(rgb),
            Err(e) => failed.add(*pos, || {
                format!("{} (material `{}`): {e}", path.display(), m.name)
            }),
        }
    }
    if let Some((pos, first)) = failed.first {
        lib.warnings.push(Warning::at(
            &lib.file,
            pos,
            format!(
                "cannot read {} `map_Kd` texture(s), first {first}; their materials keep `Kd`",
                failed.count
            ),
        ));
    }
    if let Some((pos, first)) = lib.backslashes.first.take() {
        lib.warnings.push(Warning::at(
            &lib.file,
            pos,
            format!(
                "{} `map_Kd` path(s) written with `\\` (first `{first}`), read with `/`",
                lib.backslashes.count
            ),
        ));
    }
}

/// The colour of a `Kd`/`Ke` line: `r g b`, or one value for grey (as the
/// MTL format allows). Each finite and `>= 0`. Errors carry the column.
pub(super) fn color(w: &[(&str, u32)]) -> Result<Rgb, (u32, String)> {
    let (keyword, col) = w[0];
    let values = &w[1..];
    if let Some(&(word, c)) = values
        .first()
        .filter(|(x, _)| *x == "spectral" || *x == "xyz")
    {
        return Err((
            c,
            format!("`{keyword} {word}` is not supported: give r g b values"),
        ));
    }
    if values.len() != 1 && values.len() != 3 {
        return Err((
            col,
            format!(
                "`{keyword}` takes 3 numbers (r g b) or 1 (grey), found {}",
                values.len()
            ),
        ));
    }
    let mut out = [0.0f64; 3];
    for (slot, &(word, c)) in out.iter_mut().zip(values) {
        let x = match word.parse::<f64>() {
            Ok(x) if x.is_finite() => x,
            Ok(_) => {
                return Err((
                    c,
                    format!("`{word}` is not allowed: numbers must be finite"),
                ))
            }
            Err(_) => return Err((c, format!("invalid number `{word}`"))),
        };
        if x < 0.0 {
            return Err((c, negative_channel(keyword, word)));
        }
        *slot = x;
    }
    if values.len() == 1 {
        out = [out[0]; 3];
    }
    Ok(Rgb::new(out[0], out[1], out[2]))
}
