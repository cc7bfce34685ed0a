//! Turns the window's per-frame pointer state into drags.
//!
//! The window library reads the pointer position when a frame starts and
//! the buttons from the events that arrived since the last frame, so on a
//! busy machine a press or a release is often seen a frame after the
//! pointer has moved past it. A drag here is therefore the way from where
//! the pointer was in the last frame before the press was seen to where it
//! is in the first frame after the release was seen: the motion of a frame
//! belongs to the drag when a button was down at either end of it. Pure
//! bookkeeping, so it is tested without a window.

/// Which mouse buttons are down.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Buttons {
    /// The left button.
    pub left: bool,
    /// The right button.
    pub right: bool,
}

impl Buttons {
    /// True when either button is down.
    pub fn any(self) -> bool {
        self.left || self.right
    }
}

/// What the pointer did in one frame, as far as drags go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Set on the frame a drag starts: where it was pressed (window
    /// pixels), i.e. where the pointer was last seen before the press.
    pub pressed_at: Option<(f32, f32)>,
    /// The buttons the frame's motion drags with: those down at either end
    /// of the frame.
    pub buttons: Buttons,
    /// How far the pointer moved in the frame (window pixels, x right,
    /// y down); zero when no button was down at either end.
    pub delta: (f32, f32),
}

/// The pointer as seen at the last frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct Pointer {
    last: Option<(f32, f32)>,
    held: Buttons,
}

impl Pointer {
    /// Takes a frame's pointer position (`None` when unknown) and buttons,
    /// and says what they drag.
    pub fn frame(&mut self, pos: Option<(f32, f32)>, now: Buttons) -> Motion {
        let buttons = Buttons {
            left: now.left || self.held.left,
            right: now.right || self.held.right,
        };
        let pressed_at = (now.any() && !self.held.any())
            .then(|| self.last.or(pos))
            .flatten();
        let delta = match (pos, self.last) {
            (Some((x, y)), Some((x0, y0))) if buttons.any() => (x - x0, y - y0),
            _ => (0.0, 0.0),
        };
        self.last = pos;
        self.held = now;
        Motion {
            pressed_at,
            buttons,
            delta,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const UP: Buttons = Buttons {
        left: false,
        right: false,
    };
    const LEFT: Buttons = Buttons {
        left: true,
        right: false,
    };

    /// The total of a sequence of frames' deltas.
    fn drag(frames: &[((f32, f32), Buttons)]) -> (f32, f32) {
        let mut pointer = Pointer::default();
        frames.iter().fold((0.0, 0.0), |(sx, sy), &(pos, b)| {
            let m = pointer.frame(Some(pos), b);
            (sx + m.delta.0, sy + m.delta.1)
        })
    }

    #[test]
    fn a_drag_seen_in_time_moves_by_the_pointers_way() {
        let frames = [
            ((80.0, 60.0), UP),
            ((80.0, 60.0), LEFT),
            ((110.0, 44.0), LEFT),
            ((140.0, 28.0), LEFT),
            ((140.0, 28.0), UP),
            ((10.0, 10.0), UP),
        ];
        assert_eq!(drag(&frames), (60.0, -32.0));
    }

    #[test]
    fn a_press_and_a_release_seen_late_lose_no_motion() {
        // Out and back: the press is first seen after two motions, the
        // release together with the last two. The drag is still nil; the
        // pointer's moves before the press and after the release are not
        // part of it.
        let frames = [
            ((0.0, 0.0), UP),
            ((80.0, 60.0), UP),
            ((140.0, 28.0), LEFT),
            ((170.0, 12.0), LEFT),
            ((110.0, 44.0), LEFT),
            ((80.0, 60.0), UP),
            ((0.0, 0.0), UP),
        ];
        assert_eq!(drag(&frames), (0.0, 0.0));
    }

    #[test]
    fn the_press_point_is_where_the_pointer_was_before_the_press_was_seen() {
        let mut pointer = Pointer::default();
        assert_eq!(pointer.frame(Some((5.0, 6.0)), UP).pressed_at, None);
        let m = pointer.frame(Some((9.0, 9.0)), LEFT);
        assert_eq!(m.pressed_at, Some((5.0, 6.0)));
        assert!(m.buttons.left && !m.buttons.right);
        // Only on the frame the drag starts.
        assert_eq!(pointer.frame(Some((12.0, 9.0)), LEFT).pressed_at, None);
        // The release frame still drags with the left button.
        let last = pointer.frame(Some((15.0, 9.0)), UP);
        assert!(last.buttons.left);
        assert_eq!(last.delta, (3.0, 0.0));
        // Then nothing moves the camera.
        let idle = pointer.frame(Some((50.0, 50.0)), UP);
        assert!(!idle.buttons.any());
        assert_eq!(idle.delta, (0.0, 0.0));
    }

    #[test]
    fn an_unknown_position_moves_nothing() {
        let mut pointer = Pointer::default();
        pointer.frame(None, LEFT);
        assert_eq!(pointer.frame(Some((3.0, 4.0)), LEFT).delta, (0.0, 0.0));
        assert_eq!(pointer.frame(None, LEFT).delta, (0.0, 0.0));
    }
}
