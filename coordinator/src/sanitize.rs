//! Text a peer sent (a worker's host name, software name, error messages), made safe to print
//! on a terminal or write to a report: a hostile worker must not be able to move the cursor,
//! retitle the window, clear the screen or reorder what the user reads. A leaf: it imports
//! nothing from the crate.

/// What replaces each control or formatting character.
const REPLACEMENT: char = '\u{FFFD}';

/// `text` with every control character (C0, DEL, C1: the escape sequences' introducers and
/// terminators, newlines included) and every invisible formatting character (bidirectional
/// overrides, zero-width characters) replaced by U+FFFD, cut to at most `max_chars`
/// characters (an ellipsis marks the cut).
pub fn peer_text(text: &str, max_chars: usize) -> String {
    let mut out: String = text
        .chars()
        .take(max_chars)
        .map(|c| if is_unsafe(c) { REPLACEMENT } else { c })
        .collect();
    if text.chars().nth(max_chars).is_some() {
        out.pop();
        out.push('…');
    }
    out
}

fn is_unsafe(c: char) -> bool {
    c.is_control()
        || matches!(c,
            '\u{200B}'..='\u{200F}' // zero-width characters, left-to-right and right-to-left marks
            | '\u{2028}'..='\u{202E}' // line and paragraph separators, bidirectional embeddings
            | '\u{2060}'..='\u{2069}' // word joiner, invisible operators, bidirectional isolates
            | '\u{FEFF}') // zero-width no-break space
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escape_sequences_and_controls_are_replaced() {
        let hostile = "node\x1b]0;pwn\x07\x1b[2J\r\nfake: ok\u{9b}31m\u{202e}gnp.exe\u{7f}";
        let safe = peer_text(hostile, 100);
        assert!(
            safe.chars().all(|c| !c.is_control() && c != '\u{202e}'),
            "{safe:?}"
        );
        assert_eq!(
            safe,
            "node\u{fffd}]0;pwn\u{fffd}\u{fffd}[2J\u{fffd}\u{fffd}fake: ok\u{fffd}31m\u{fffd}gnp.exe\u{fffd}"
        );
        assert_eq!(
            peer_text("worker-1.example.org", 100),
            "worker-1.example.org"
        );
        assert_eq!(peer_text("héllo wörld", 100), "héllo wörld");
    }

    #[test]
    fn long_text_is_cut_with_a_mark() {
        assert_eq!(peer_text("abcdef", 6), "abcdef");
        assert_eq!(peer_text("abcdefg", 6), "abcde…");
        assert_eq!(peer_text(&"é".repeat(10_000), 64).chars().count(), 64);
    }
}
