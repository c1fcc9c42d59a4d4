//! Byte-level tokenizer for LuxRender scene text. Geometry files are mostly numbers, so a number
//! is parsed straight from the input bytes into an `f64` (no per-token `String`), and positions
//! are tracked incrementally (line counter plus the offset where the line starts).

use std::borrow::Cow;

/// Line and column (both 1-based, column in bytes) of a token in its file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineCol {
    pub line: u32,
    pub column: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub enum TokenKind<'a> {
    /// A bare word: a statement keyword.
    Ident(&'a str),
    /// A quoted string, escapes already resolved.
    Str(Cow<'a, str>),
    Num(f64),
    LBracket,
    RBracket,
    Eof,
}

impl TokenKind<'_> {
    /// How an error message names this token.
    pub fn describe(&self) -> String {
        match self {
            TokenKind::Ident(s) => format!("keyword `{s}`"),
            TokenKind::Str(s) => format!("string \"{s}\""),
            TokenKind::Num(v) => format!("number {v}"),
            TokenKind::LBracket => "`[`".to_string(),
            TokenKind::RBracket => "`]`".to_string(),
            TokenKind::Eof => "end of file".to_string(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Token<'a> {
    pub kind: TokenKind<'a>,
    pub at: LineCol,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LexError {
    pub at: LineCol,
    pub message: String,
}

pub struct Lexer<'a> {
    text: &'a [u8],
    offset: usize,
    line: u32,
    line_start: usize,
    peeked: Option<Token<'a>>,
}

impl<'a> Lexer<'a> {
    pub fn new(text: &'a [u8]) -> Self {
        // A UTF-8 byte order mark is not part of the first statement.
        let offset = if text.starts_with(b"\xEF\xBB\xBF") {
            3
        } else {
            0
        };
        Self {
            text,
            offset,
            line: 1,
            line_start: 0,
            peeked: None,
        }
    }

    pub fn peek(&mut self) -> Result<&Token<'a>, LexError> {
        if self.peeked.is_none() {
            self.peeked = Some(self.scan()?);
        }
        Ok(self.peeked.as_ref().expect("just filled"))
    }

    /// The token a successful [`Lexer::peek`] looked at.
    pub fn peeked(&self) -> Option<&Token<'a>> {
        self.peeked.as_ref()
    }

    pub fn next_token(&mut self) -> Result<Token<'a>, LexError> {
        match self.peeked.take() {
            Some(t) => Ok(t),
            None => self.scan(),
        }
    }

    fn here(&self) -> LineCol {
        LineCol {
            line: self.line,
            column: (self.offset - self.line_start + 1) as u32,
        }
    }

    fn skip_blanks_and_comments(&mut self) {
        while let Some(&b) = self.text.get(self.offset) {
            match b {
                b'\n' => {
                    self.offset += 1;
                    self.line += 1;
                    self.line_start = self.offset;
                }
                b' ' | b'\t' | b'\r' | b'\x0c' => self.offset += 1,
                b'#' => {
                    while self.offset < self.text.len() && self.text[self.offset] != b'\n' {
                        self.offset += 1;
                    }
                }
                _ => break,
            }
        }
    }

    fn scan(&mut self) -> Result<Token<'a>, LexError> {
        self.skip_blanks_and_comments();
        let at = self.here();
        let Some(&b) = self.text.get(self.offset) else {
            return Ok(Token {
                kind: TokenKind::Eof,
                at,
            });
        };
        let kind = match b {
            b'[' => {
                self.offset += 1;
                TokenKind::LBracket
            }
            b']' => {
                self.offset += 1;
                TokenKind::RBracket
            }
            b'"' => TokenKind::Str(self.scan_string(at)?),
            b'0'..=b'9' | b'+' | b'-' | b'.' => TokenKind::Num(self.scan_number(at)?),
            b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                let start = self.offset;
                while self
                    .text
                    .get(self.offset)
                    .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
                {
                    self.offset += 1;
                }
                TokenKind::Ident(ascii_str(&self.text[start..self.offset]))
            }
            _ => {
                return Err(LexError {
                    at,
                    message: format!(
                        "unexpected character {}",
                        describe_byte(self.text, self.offset)
                    ),
                })
            }
        };
        Ok(Token { kind, at })
    }

    fn scan_number(&mut self, at: LineCol) -> Result<f64, LexError> {
        let start = self.offset;
        while self
            .text
            .get(self.offset)
            .is_some_and(|c| matches!(c, b'0'..=b'9' | b'+' | b'-' | b'.' | b'e' | b'E'))
        {
            self.offset += 1;
        }
        let digits = ascii_str(&self.text[start..self.offset]);
        digits.parse::<f64>().map_err(|_| LexError {
            at,
            message: format!("invalid number `{digits}`"),
        })
    }

    fn scan_string(&mut self, at: LineCol) -> Result<Cow<'a, str>, LexError> {
        let start = self.offset + 1;
        let mut end = start;
        let mut has_escape = false;
        loop {
            match self.text.get(end) {
                Some(b'"') => break,
                Some(b'\\') => {
                    has_escape = true;
                    end += 2;
                }
                Some(b'\n') | None => {
                    return Err(LexError {
                        at,
                        message: "unterminated string (a string must close on its own line)"
                            .to_string(),
                    })
                }
                Some(_) => end += 1,
            }
        }
        self.offset = end + 1;
        let raw = &self.text[start..end];
        let text = String::from_utf8_lossy(raw);
        if !has_escape {
            return Ok(text);
        }
        let mut out = String::with_capacity(text.len());
        let mut chars = text.chars();
        while let Some(c) = chars.next() {
            if c != '\\' {
                out.push(c);
                continue;
            }
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(other) => out.push(other),
                None => {}
            }
        }
        Ok(Cow::Owned(out))
    }
}

/// The scanner only slices runs of ASCII bytes it has checked itself.
fn ascii_str(bytes: &[u8]) -> &str {
    std::str::from_utf8(bytes).expect("scanner slices ASCII runs only")
}

fn describe_byte(text: &[u8], offset: usize) -> String {
    let b = text[offset];
    if b.is_ascii_graphic() {
        format!("`{}`", b as char)
    } else {
        format!("byte 0x{b:02x}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str) -> Vec<TokenKind<'_>> {
        let mut lx = Lexer::new(text.as_bytes());
        let mut out = Vec::new();
        loop {
            let t = lx.next_token().unwrap();
            if t.kind == TokenKind::Eof {
                return out;
            }
            out.push(t.kind);
        }
    }

    #[test]
    fn tokens_and_comments() {
        let k = kinds("Shape \"mesh\" # a comment [ 1 2\n \"point P\" [-1.5e2 +3 .5]");
        assert_eq!(
            k,
            vec![
                TokenKind::Ident("Shape"),
                TokenKind::Str("mesh".into()),
                TokenKind::Str("point P".into()),
                TokenKind::LBracket,
                TokenKind::Num(-150.0),
                TokenKind::Num(3.0),
                TokenKind::Num(0.5),
                TokenKind::RBracket,
            ]
        );
    }

    #[test]
    fn positions_are_line_and_column() {
        let mut lx = Lexer::new(b"A\n  \"b\"\n\t\t7");
        let a = lx.next_token().unwrap();
        let b = lx.next_token().unwrap();
        let c = lx.next_token().unwrap();
        assert_eq!((a.at.line, a.at.column), (1, 1));
        assert_eq!((b.at.line, b.at.column), (2, 3));
        assert_eq!((c.at.line, c.at.column), (3, 3));
    }

    #[test]
    fn errors_name_the_position() {
        let mut lx = Lexer::new(b"Foo\n  1.2.3");
        lx.next_token().unwrap();
        let e = lx.next_token().unwrap_err();
        assert_eq!((e.at.line, e.at.column), (2, 3));
        assert!(e.message.contains("1.2.3"), "{}", e.message);
        let e = Lexer::new(b"\"open").next_token().unwrap_err();
        assert!(e.message.contains("unterminated"));
        let e = Lexer::new(b"\x00\x01").next_token().unwrap_err();
        assert!(e.message.contains("0x00"), "{}", e.message);
    }

    #[test]
    fn escapes_and_non_utf8_strings() {
        assert_eq!(kinds(r#""a\"b""#), vec![TokenKind::Str("a\"b".into())]);
        let k = kinds_bytes(b"\"caf\xe9\"");
        assert!(matches!(&k[0], TokenKind::Str(s) if s.starts_with("caf")));
    }

    fn kinds_bytes(text: &[u8]) -> Vec<TokenKind<'_>> {
        let mut lx = Lexer::new(text);
        vec![lx.next_token().unwrap().kind]
    }
}
