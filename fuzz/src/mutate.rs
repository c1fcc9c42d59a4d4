//! Mutations of one input's bytes, blind to what the bytes mean: byte-level edits (flips,
//! random bytes, deleted, duplicated and inserted ranges), token-level edits for text
//! (whitespace-separated words, quoted strings and brackets deleted, duplicated, swapped or
//! replaced), numbers changed to extremes, nested brackets, unterminated strings, and splices
//! of two inputs. Every result is at most [`Mutator::max_len`] bytes.

use fastrand::Rng;

/// Numbers that break arithmetic: zero, signs, the edges of f32, u32 and i32, overflow to
/// infinity when parsed as f32, NaN and infinity spelled out, denormals.
const EXTREME_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1",
    "2",
    "1e38",
    "3e38",
    "-3e38",
    "3.5e38",
    "1e39",
    "1e400",
    "-1e400",
    "1e-45",
    "1e-300",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "4294967295",
    "4294967296",
    "2147483647",
    "2147483648",
    "-2147483648",
    "-2147483649",
    "18446744073709551616",
    "99999999999999999999999",
    "65536",
    "1000000000",
    "0.5",
    "1e9",
    "-1e9",
    "360",
    "180",
    "90",
];

/// Texts that are valid tokens somewhere, or famously not: brackets, quotes, escapes,
/// comments, non-ASCII, control bytes.
const ODD_TOKENS: &[&str] = &[
    "[",
    "]",
    "[[[[[[[[",
    "]]]]]]]]",
    "[]",
    "\"",
    "\"\"",
    "\"unterminated",
    "\"\\",
    "\"\\\"",
    "#",
    "#comment\n",
    "\n",
    "\r\n",
    "\t",
    "\0",
    "\u{fffd}",
    "\u{e9}t\u{e9}",
    "\u{1F600}",
    "\\",
    "-",
    ".",
    "e",
    "1e",
    "--1",
    "1.2.3",
    "0x10",
    "+",
];

/// Byte and token mutations of inputs up to `max_len` bytes, with a dictionary of words
/// (keywords, parameter declarations, file names) the input's format knows.
pub struct Mutator {
    pub max_len: usize,
    dictionary: Vec<Vec<u8>>,
}

/// A token's place in a text: `start..end` bytes.
type Span = std::ops::Range<usize>;

impl Mutator {
    pub fn new(max_len: usize, dictionary: &[&str]) -> Self {
        let mut words: Vec<Vec<u8>> = dictionary.iter().map(|w| w.as_bytes().to_vec()).collect();
        words.extend(EXTREME_NUMBERS.iter().map(|w| w.as_bytes().to_vec()));
        words.extend(ODD_TOKENS.iter().map(|w| w.as_bytes().to_vec()));
        Self {
            max_len,
            dictionary: words,
        }
    }

    /// Applies one mutation, sometimes a few, to `data`; `other` is a second input to splice
    /// from. Most mutations keep the text well formed (numbers made extreme, whole lines
    /// moved), so inputs get past the lexer to the code behind it.
    pub fn mutate(&self, rng: &mut Rng, data: &mut Vec<u8>, other: &[u8]) {
        let mut count = 1;
        while count < 4 && rng.bool() {
            count += 1;
        }
        for _ in 0..count {
            self.mutate_once(rng, data, other);
        }
        data.truncate(self.max_len);
    }

    fn mutate_once(&self, rng: &mut Rng, data: &mut Vec<u8>, other: &[u8]) {
        match rng.u32(0..32) {
            0..=7 => self.replace_token(rng, data, TokenChoice::Number),
            8 => delete_line(rng, data),
            9 | 10 => duplicate_line(rng, data),
            11 => swap_lines(rng, data),
            12 | 13 => insert_line_from(rng, data, other),
            14 | 15 => self.replace_token(rng, data, TokenChoice::Str),
            16 => self.replace_token(rng, data, TokenChoice::Any),
            17 => delete_token(rng, data),
            18 => duplicate_token(rng, data),
            19 => swap_tokens(rng, data),
            20 => repeat_token(rng, data),
            21 => flip_bit(rng, data),
            22 => set_random_byte(rng, data),
            23 => insert_random_bytes(rng, data),
            24 => delete_range(rng, data),
            25 => duplicate_range(rng, data),
            26 => splice(rng, data, other),
            27 => nest_brackets(rng, data),
            28 => unterminate_string(rng, data),
            _ => self.insert_word(rng, data),
        }
    }

    fn word<'a>(&'a self, rng: &mut Rng) -> &'a [u8] {
        &self.dictionary[rng.usize(0..self.dictionary.len())]
    }

    fn insert_word(&self, rng: &mut Rng, data: &mut Vec<u8>) {
        let at = rng.usize(0..=data.len());
        let mut word = vec![b' '];
        word.extend_from_slice(self.word(rng));
        word.push(b' ');
        data.splice(at..at, word);
    }

    fn replace_token(&self, rng: &mut Rng, data: &mut Vec<u8>, choice: TokenChoice) {
        let tokens = tokens(data);
        let candidates: Vec<&Span> = match choice {
            TokenChoice::Any => tokens.iter().collect(),
            TokenChoice::Number => tokens
                .iter()
                .filter(|t| is_number(&data[(*t).clone()]))
                .collect(),
            TokenChoice::Str => tokens.iter().filter(|t| data[t.start] == b'"').collect(),
        };
        if candidates.is_empty() {
            return self.insert_word(rng, data);
        }
        let span = candidates[rng.usize(0..candidates.len())].clone();
        let replacement = match choice {
            TokenChoice::Number => EXTREME_NUMBERS[rng.usize(0..EXTREME_NUMBERS.len())]
                .as_bytes()
                .to_vec(),
            TokenChoice::Str => {
                let quoted: Vec<&Vec<u8>> = self
                    .dictionary
                    .iter()
                    .filter(|w| w.first() == Some(&b'"'))
                    .collect();
                match quoted.len() {
                    0 => self.word(rng).to_vec(),
                    n => quoted[rng.usize(0..n)].clone(),
                }
            }
            TokenChoice::Any => self.word(rng).to_vec(),
        };
        data.splice(span, replacement);
    }
}

#[derive(Clone, Copy)]
enum TokenChoice {
    Any,
    Number,
    Str,
}

fn range(rng: &mut Rng, len: usize) -> Span {
    if len == 0 {
        return 0..0;
    }
    let start = rng.usize(0..len);
    // Mostly short ranges, sometimes long ones.
    let max = if rng.u8(0..8) == 0 {
        len - start
    } else {
        (len - start).min(16)
    };
    start..start + rng.usize(1..=max)
}

fn flip_bit(rng: &mut Rng, data: &mut [u8]) {
    if !data.is_empty() {
        let i = rng.usize(0..data.len());
        data[i] ^= 1 << rng.u8(0..8);
    }
}

fn set_random_byte(rng: &mut Rng, data: &mut [u8]) {
    if !data.is_empty() {
        let i = rng.usize(0..data.len());
        data[i] = rng.u8(..);
    }
}

fn insert_random_bytes(rng: &mut Rng, data: &mut Vec<u8>) {
    let at = rng.usize(0..=data.len());
    let n = rng.usize(1..=8);
    data.splice(at..at, std::iter::repeat_with(|| rng.u8(..)).take(n));
}

fn delete_range(rng: &mut Rng, data: &mut Vec<u8>) {
    let r = range(rng, data.len());
    data.drain(r);
}

fn duplicate_range(rng: &mut Rng, data: &mut Vec<u8>) {
    let r = range(rng, data.len());
    let copy = data[r.clone()].to_vec();
    let at = rng.usize(0..=data.len());
    data.splice(at..at, copy);
}

/// A prefix of `data` followed by a suffix of `other`.
fn splice(rng: &mut Rng, data: &mut Vec<u8>, other: &[u8]) {
    let cut = rng.usize(0..=data.len());
    let from = rng.usize(0..=other.len());
    data.truncate(cut);
    data.extend_from_slice(&other[from..]);
}

/// The byte ranges of the lines of `data`, each with its newline.
fn lines(data: &[u8]) -> Vec<Span> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &b) in data.iter().enumerate() {
        if b == b'\n' {
            out.push(start..i + 1);
            start = i + 1;
        }
    }
    if start < data.len() {
        out.push(start..data.len());
    }
    out
}

fn delete_line(rng: &mut Rng, data: &mut Vec<u8>) {
    if let Some(line) = pick(rng, &lines(data)) {
        data.drain(line);
    }
}

fn duplicate_line(rng: &mut Rng, data: &mut Vec<u8>) {
    let lines = lines(data);
    if let (Some(line), Some(at)) = (pick(rng, &lines), pick(rng, &lines)) {
        let copy = with_newline(&data[line]);
        data.splice(at.start..at.start, copy);
    }
}

fn swap_lines(rng: &mut Rng, data: &mut Vec<u8>) {
    let lines = lines(data);
    let (Some(a), Some(b)) = (pick(rng, &lines), pick(rng, &lines)) else {
        return;
    };
    let (first, second) = if a.start <= b.start { (a, b) } else { (b, a) };
    if first.start == second.start {
        return;
    }
    let mut out = Vec::with_capacity(data.len() + 2);
    out.extend_from_slice(&data[..first.start]);
    out.extend(with_newline(&data[second.clone()]));
    out.extend_from_slice(&data[first.end..second.start]);
    out.extend(with_newline(&data[first.clone()]));
    out.extend_from_slice(&data[second.end..]);
    *data = out;
}

/// A line of `other` (a statement of another scene, often) inserted between two lines.
fn insert_line_from(rng: &mut Rng, data: &mut Vec<u8>, other: &[u8]) {
    let Some(line) = pick(rng, &lines(other)) else {
        return;
    };
    let at = pick(rng, &lines(data)).map_or(0, |l| l.start);
    data.splice(at..at, with_newline(&other[line]));
}

fn with_newline(line: &[u8]) -> Vec<u8> {
    let mut out = line.to_vec();
    if out.last() != Some(&b'\n') {
        out.push(b'\n');
    }
    out
}

fn delete_token(rng: &mut Rng, data: &mut Vec<u8>) {
    if let Some(span) = pick(rng, &tokens(data)) {
        data.drain(span);
    }
}

fn duplicate_token(rng: &mut Rng, data: &mut Vec<u8>) {
    let tokens = tokens(data);
    if let (Some(span), Some(at)) = (pick(rng, &tokens), pick(rng, &tokens)) {
        let mut copy = data[span].to_vec();
        copy.push(b' ');
        data.splice(at.start..at.start, copy);
    }
}

fn swap_tokens(rng: &mut Rng, data: &mut Vec<u8>) {
    let tokens = tokens(data);
    let (Some(a), Some(b)) = (pick(rng, &tokens), pick(rng, &tokens)) else {
        return;
    };
    let (first, second) = if a.start <= b.start { (a, b) } else { (b, a) };
    if first.end > second.start {
        return;
    }
    let mut out = Vec::with_capacity(data.len());
    out.extend_from_slice(&data[..first.start]);
    out.extend_from_slice(&data[second.clone()]);
    out.extend_from_slice(&data[first.end..second.start]);
    out.extend_from_slice(&data[first.clone()]);
    out.extend_from_slice(&data[second.end..]);
    *data = out;
}

/// A token repeated many times: huge counts of numbers, statements or parameters.
fn repeat_token(rng: &mut Rng, data: &mut Vec<u8>) {
    if let Some(span) = pick(rng, &tokens(data)) {
        let mut token = data[span.clone()].to_vec();
        token.push(b' ');
        let times = rng.usize(2..=512);
        let repeated = token.repeat(times);
        data.splice(span.end..span.end, repeated);
    }
}

fn nest_brackets(rng: &mut Rng, data: &mut Vec<u8>) {
    let at = rng.usize(0..=data.len());
    let depth = rng.usize(1..=64);
    let mut nested = vec![b'['; depth];
    if rng.bool() {
        nested.extend(std::iter::repeat_n(b']', depth));
    }
    data.splice(at..at, nested);
}

/// Drops a string's closing quote.
fn unterminate_string(rng: &mut Rng, data: &mut Vec<u8>) {
    let strings: Vec<Span> = tokens(data)
        .into_iter()
        .filter(|t| t.len() >= 2 && data[t.start] == b'"' && data[t.end - 1] == b'"')
        .collect();
    if let Some(span) = pick(rng, &strings) {
        data.remove(span.end - 1);
    }
}

fn pick(rng: &mut Rng, spans: &[Span]) -> Option<Span> {
    (!spans.is_empty()).then(|| spans[rng.usize(0..spans.len())].clone())
}

fn is_number(token: &[u8]) -> bool {
    token
        .first()
        .is_some_and(|b| b.is_ascii_digit() || matches!(b, b'-' | b'+' | b'.'))
}

/// The tokens of a text as the scene lexer sees them, roughly: quoted strings (to the closing
/// quote or the end), single brackets, and runs of other non-space bytes.
pub fn tokens(data: &[u8]) -> Vec<Span> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < data.len() {
        let b = data[i];
        if b.is_ascii_whitespace() {
            i += 1;
        } else if b == b'"' {
            let end = data[i + 1..]
                .iter()
                .position(|&c| c == b'"')
                .map_or(data.len(), |p| i + 2 + p);
            out.push(i..end);
            i = end;
        } else if b == b'[' || b == b']' {
            out.push(i..i + 1);
            i += 1;
        } else {
            let start = i;
            while i < data.len()
                && !data[i].is_ascii_whitespace()
                && !matches!(data[i], b'"' | b'[' | b']')
            {
                i += 1;
            }
            out.push(start..i);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_split_strings_brackets_and_words() {
        let text = br#"Shape "sphere" "float radius" [1.5] "unterminated"#;
        let words: Vec<&[u8]> = tokens(text).into_iter().map(|s| &text[s]).collect();
        assert_eq!(
            words,
            [
                &b"Shape"[..],
                b"\"sphere\"",
                b"\"float radius\"",
                b"[",
                b"1.5",
                b"]",
                b"\"unterminated"
            ]
        );
    }

    #[test]
    fn mutations_stay_within_the_length_bound_and_change_the_input() {
        let mutator = Mutator::new(256, &["WorldBegin"]);
        let mut rng = Rng::with_seed(3);
        let seed = b"Shape \"sphere\" \"float radius\" [1] # x\n".repeat(4);
        let mut changed = 0;
        for _ in 0..2000 {
            let mut data = seed.clone();
            mutator.mutate(&mut rng, &mut data, b"Translate 1 2 3");
            assert!(data.len() <= 256);
            changed += usize::from(data != seed);
        }
        assert!(changed > 1900, "{changed} of 2000 inputs changed");
    }
}
