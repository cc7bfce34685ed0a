//! What a picture shows, pixel by pixel: background, the backs of
//! polygons (no light; striped blue-grey in 8-bit pictures), front faces with no light, or lit front faces; and the one
//! warning a (nearly) black picture deserves.
//!
//! Polygons are one-sided, so a picture can come out black for reasons the
//! picture itself cannot tell a user: the camera stands outside a closed
//! room (every wall shows its back, or its unlit outside), the lights do
//! not reach what is seen, or the camera looks past the scene. The counts
//! tell most of them apart; whether the eye stands outside the room that
//! holds the lights is asked of the scene by the caller
//! ([`PictureCoverage::dark_warning_with`]). A scene where nothing emits
//! gets no such warning: loading has said so already.

use super::raster::Frame;

/// A picture is (nearly) black, and worth a warning, when more than this
/// fraction of its pixels (dimensionless) are background, back faces or
/// unlit front faces. 0.95 leaves room for a few lit pixels (a lamp seen
/// through a gap, the edge of a wall) in a picture that is still useless.
pub const DARK_PICTURE_FRACTION: f64 = 0.95;

/// How many pixels of a picture show what.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PictureCoverage {
    /// Every pixel of the picture.
    pub pixels: usize,
    /// Pixels no surface covers.
    pub background: usize,
    /// Pixels whose nearest surface is seen from the back (no light;
    /// [`super::back_face_color`] in 8-bit pictures).
    pub back_faces: usize,
    /// Pixels whose nearest surface is a front face with no light on it
    /// (no channel above zero).
    pub unlit_front: usize,
}

impl PictureCoverage {
    /// Counts the pixels of `frame`, with `front` the rasterizer's
    /// per-pixel front-face flags ([`super::Rasterizer::front_faces`]);
    /// a pixel with no flag counts as a back face when covered.
    pub fn of(frame: &Frame, front: &[bool]) -> PictureCoverage {
        let mut c = PictureCoverage {
            pixels: frame.pixels.len(),
            ..PictureCoverage::default()
        };
        for (i, (pixel, &covered)) in frame.pixels.iter().zip(&frame.covered).enumerate() {
            if !covered {
                c.background += 1;
            } else if !front.get(i).copied().unwrap_or(false) {
                c.back_faces += 1;
            } else if !pixel.iter().any(|&v| v > 0.0) {
                c.unlit_front += 1;
            }
        }
        c
    }

    /// Pixels that show nothing: background, back faces and unlit front
    /// faces.
    pub fn dark(&self) -> usize {
        self.background + self.back_faces + self.unlit_front
    }

    /// The warning for a picture more than [`DARK_PICTURE_FRACTION`] dark,
    /// one line without the `warning: ` prefix, naming the likely reason
    /// from the largest of the three kinds of dark pixel; `None` for a
    /// picture worth looking at (or one with no pixels). See
    /// [`PictureCoverage::dark_warning_with`] for the reason the pixels
    /// cannot tell.
    pub fn dark_warning(&self) -> Option<String> {
        self.dark_warning_with(|| false)
    }

    /// [`PictureCoverage::dark_warning`], asking `eye_outside_lights`
    /// (only when the picture is dark) whether the camera stands outside
    /// a closed surface that holds the lights
    /// ([`crate::scene::Scene::eye_outside_lights`]): then that is the
    /// reason, whatever the pixels show (the unlit outside of the room,
    /// background around it, or the backs of its walls).
    pub fn dark_warning_with(&self, eye_outside_lights: impl FnOnce() -> bool) -> Option<String> {
        if self.pixels == 0 || (self.dark() as f64) <= DARK_PICTURE_FRACTION * self.pixels as f64 {
            return None;
        }
        let percent = |n: usize| 100.0 * n as f64 / self.pixels as f64;
        let reason = if eye_outside_lights() {
            "the camera stands outside the closed surface that holds the lights (a room seen \
             from outside); put the eye inside with --eye X,Y,Z and --look-at X,Y,Z, or \
             --camera FILE.sc"
                .to_string()
        } else if self.back_faces >= self.background && self.back_faces >= self.unlit_front {
            format!(
                "{:.0}% of it shows the backs of polygons, which receive no light and are \
                 drawn in dim blue-grey stripes (polygons are one-sided): the camera is probably \
                 outside a closed room, or the faces point away from it; put the eye inside with \
                 --eye X,Y,Z and --look-at X,Y,Z, or --camera FILE.sc",
                percent(self.back_faces)
            )
        } else if self.unlit_front >= self.background {
            format!(
                "{:.0}% of it shows front faces that receive no light: the lights do not reach \
                 what the camera sees (they may be hidden from it, or in another room)",
                percent(self.unlit_front)
            )
        } else {
            format!(
                "{:.0}% of it is background: the camera looks past the scene",
                percent(self.background)
            )
        };
        Some(format!(
            "the picture is nearly black ({:.0}% of its pixels): {reason}",
            percent(self.dark())
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10x10 frame: the first `lit` pixels lit front faces, then
    /// `unlit` unlit front faces, then `back` back faces; the rest
    /// background.
    fn frame(lit: usize, unlit: usize, back: usize) -> (Frame, Vec<bool>) {
        let mut f = Frame::new(10, 10);
        let mut front = vec![false; 100];
        for (i, is_front) in front.iter_mut().enumerate().take(lit + unlit + back) {
            f.covered[i] = true;
            *is_front = i < lit + unlit;
            if i < lit {
                f.pixels[i] = [0.5, 0.0, 0.0];
            }
        }
        (f, front)
    }

    fn warning(lit: usize, unlit: usize, back: usize) -> Option<String> {
        let (f, front) = frame(lit, unlit, back);
        PictureCoverage::of(&f, &front).dark_warning()
    }

    #[test]
    fn counts_each_kind() {
        let (f, front) = frame(10, 20, 30);
        let c = PictureCoverage::of(&f, &front);
        assert_eq!(
            c,
            PictureCoverage {
                pixels: 100,
                background: 40,
                back_faces: 30,
                unlit_front: 20,
            }
        );
        assert_eq!(c.dark(), 90);
    }

    #[test]
    fn a_lit_picture_gets_no_warning() {
        assert_eq!(warning(100, 0, 0), None);
        // Exactly at the limit: 95 dark pixels of 100 is still fine.
        assert_eq!(warning(5, 0, 95), None);
        assert_eq!(PictureCoverage::default().dark_warning(), None);
    }

    #[test]
    fn the_warning_names_the_largest_kind() {
        let back = warning(2, 10, 80).unwrap();
        assert!(
            back.contains("backs of polygons") && back.contains("98%"),
            "{back}"
        );
        let unlit = warning(0, 60, 10).unwrap();
        assert!(unlit.contains("no light"), "{unlit}");
        assert!(unlit.contains("the lights do not reach"), "{unlit}");
        let past = warning(1, 10, 10).unwrap();
        assert!(past.contains("background"), "{past}");
        assert!(!back.contains('\n'));
    }

    #[test]
    fn an_eye_outside_the_lights_is_the_reason_whatever_the_pixels() {
        for (lit, unlit, back) in [(0, 0, 0), (1, 60, 10), (2, 10, 80)] {
            let (f, front) = frame(lit, unlit, back);
            let c = PictureCoverage::of(&f, &front);
            let w = c.dark_warning_with(|| true).unwrap();
            assert!(
                w.contains("the camera stands outside the closed surface that holds the lights"),
                "{w}"
            );
            assert_eq!(c.dark_warning_with(|| false), c.dark_warning());
        }
        // A lit picture asks nothing.
        let (f, front) = frame(100, 0, 0);
        let asked = std::cell::Cell::new(false);
        let none = PictureCoverage::of(&f, &front).dark_warning_with(|| {
            asked.set(true);
            true
        });
        assert_eq!(none, None);
        assert!(!asked.get());
    }
}
