//! Words for a caught panic.

use std::any::Any;

/// What a caught panic's payload says: its message when it is a `&str` or
/// a `String` (what `panic!` gives), else `None`.
pub fn panic_message(payload: &(dyn Any + Send)) -> Option<String> {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panics_words_are_found_whatever_their_type() {
        let caught = |f: fn()| std::panic::catch_unwind(f).unwrap_err();
        assert_eq!(
            panic_message(caught(|| panic!("plain")).as_ref()).as_deref(),
            Some("plain")
        );
        let n = 3;
        let formatted = std::panic::catch_unwind(move || panic!("tile {n}")).unwrap_err();
        assert_eq!(panic_message(formatted.as_ref()).as_deref(), Some("tile 3"));
        let other = std::panic::catch_unwind(|| std::panic::panic_any(7u8)).unwrap_err();
        assert_eq!(panic_message(other.as_ref()), None);
    }
}
