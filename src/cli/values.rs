//! Parsers for option values that are more than a number: each turns the
//! text into the type the library uses, or says what the text should look
//! like. clap calls them while parsing, so a bad value is a usage error
//! (exit code 2) naming the option.

use crate::solver::ShooterSamples;

/// An option value that does not parse. clap prints the message after its
/// own `invalid value 'TEXT' for '--OPTION <NAME>': `; it is still a whole
/// sentence naming the option, so it reads the same wherever it is shown.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ValueError {
    /// `--size` is not `WxH` with whole numbers of pixels, both at least 1.
    #[error("--size must look like 640x480 (whole numbers >= 1), got `{0}`")]
    Size(String),
    /// `--shooter-samples` is neither `all` nor a whole number at least 1.
    #[error("--shooter-samples must be `all` or a whole number >= 1, got `{0}`")]
    ShooterSamples(String),
}

/// Parses `--size`: `WxH` (or `WXH`), width and height in pixels, both
/// whole numbers at least 1. How large a picture may be is the renderer's
/// to say, once it knows the camera.
pub fn parse_size(text: &str) -> Result<(u32, u32), ValueError> {
    let parsed = text
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if w >= 1 && h >= 1 => Ok((w, h)),
        _ => Err(ValueError::Size(text.to_string())),
    }
}

/// Parses `--shooter-samples`: `all` ([`ShooterSamples::All`]) or a whole
/// number `N >= 1` ([`ShooterSamples::AtMost`]`(N)`).
pub fn parse_shooter_samples(text: &str) -> Result<ShooterSamples, ValueError> {
    if text == "all" {
        return Ok(ShooterSamples::All);
    }
    match text.parse::<u32>() {
        Ok(n) if n >= 1 => Ok(ShooterSamples::AtMost(n)),
        _ => Err(ValueError::ShooterSamples(text.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_width_by_height_in_whole_pixels() {
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        assert_eq!(parse_size("1X1"), Ok((1, 1)));
        for bad in [
            "10by10", "0x10", "10x0", "10x", "x10", "-1x5", "1.5x2", "", "10x10x10",
        ] {
            assert_eq!(parse_size(bad), Err(ValueError::Size(bad.into())), "{bad}");
        }
    }

    #[test]
    fn shooter_samples_are_all_or_at_least_one() {
        assert_eq!(parse_shooter_samples("all"), Ok(ShooterSamples::All));
        assert_eq!(parse_shooter_samples("1"), Ok(ShooterSamples::AtMost(1)));
        assert_eq!(
            parse_shooter_samples("256"),
            Ok(ShooterSamples::AtMost(256))
        );
        for bad in ["zero", "0", "-4", "ALL", "", "1e3"] {
            assert_eq!(
                parse_shooter_samples(bad),
                Err(ValueError::ShooterSamples(bad.into())),
                "{bad}"
            );
        }
    }

    #[test]
    fn messages_keep_their_wording() {
        assert_eq!(
            parse_size("10by10").unwrap_err().to_string(),
            "--size must look like 640x480 (whole numbers >= 1), got `10by10`"
        );
        assert_eq!(
            parse_shooter_samples("zero").unwrap_err().to_string(),
            "--shooter-samples must be `all` or a whole number >= 1, got `zero`"
        );
    }
}
