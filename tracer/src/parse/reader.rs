//! Tokens -> statement pieces. LuxRender statements are a keyword, fixed positional arguments
//! (strings or numbers, brackets optional around a numeric array) and a parameter list of
//! `"type name" value-or-[values]` pairs; a statement ends where the next keyword begins.

use super::error::ParseError;
use super::lexer::{LexError, Lexer, Token, TokenKind};
use super::params::{Param, ParamList, ParamType, Values};
use crate::diag::SourcePos as Pos;

pub struct Reader<'a> {
    lexer: Lexer<'a>,
    file: String,
}

impl<'a> Reader<'a> {
    pub fn new(file: &str, text: &'a [u8]) -> Self {
        Self {
            lexer: Lexer::new(text),
            file: file.to_string(),
        }
    }

    fn pos(&self, t: &Token) -> Pos {
        Pos::new(&self.file, t.at.line, t.at.column)
    }

    fn lex_error(&self, e: LexError) -> ParseError {
        ParseError::Syntax {
            pos: Pos::new(&self.file, e.at.line, e.at.column),
            message: e.message,
        }
    }

    fn syntax(&self, t: &Token, message: String) -> ParseError {
        ParseError::Syntax {
            pos: self.pos(t),
            message,
        }
    }

    fn next(&mut self) -> Result<Token<'a>, ParseError> {
        self.lexer.next_token().map_err(|e| self.lex_error(e))
    }

    fn peek_token(&mut self) -> Result<&Token<'a>, ParseError> {
        if let Some(e) = self.lexer.peek().err() {
            return Err(self.lex_error(e));
        }
        Ok(self.lexer.peeked().expect("peek succeeded"))
    }

    fn peek_kind(&mut self) -> Result<&TokenKind<'a>, ParseError> {
        Ok(&self.peek_token()?.kind)
    }

    /// The next statement keyword and its position, or `None` at the end of the file.
    pub fn keyword(&mut self) -> Result<Option<(&'a str, Pos)>, ParseError> {
        let t = self.next()?;
        match t.kind {
            TokenKind::Eof => Ok(None),
            TokenKind::Ident(k) => Ok(Some((k, self.pos(&t)))),
            ref other => Err(self.syntax(
                &t,
                format!("expected a statement keyword, found {}", other.describe()),
            )),
        }
    }

    /// Skips the arguments of a statement this parser does not know.
    pub fn skip_statement(&mut self) -> Result<(), ParseError> {
        while !matches!(self.peek_kind()?, TokenKind::Ident(_) | TokenKind::Eof) {
            self.next()?;
        }
        Ok(())
    }

    pub fn string(&mut self, what: &str) -> Result<String, ParseError> {
        let t = self.next()?;
        match t.kind {
            TokenKind::Str(s) => Ok(s.into_owned()),
            ref other => Err(self.syntax(
                &t,
                format!(
                    "expected {what} (a quoted string), found {}",
                    other.describe()
                ),
            )),
        }
    }

    /// Exactly `N` numbers, optionally in brackets.
    pub fn numbers<const N: usize>(&mut self, what: &str) -> Result<[f32; N], ParseError> {
        let first = self.peek_token()?.clone();
        let v = self.number_array(what)?;
        if v.len() != N {
            return Err(self.syntax(
                &first,
                format!("{what}: expected {N} numbers, found {}", v.len()),
            ));
        }
        let mut out = [0.0f32; N];
        for (o, x) in out.iter_mut().zip(&v) {
            *o = *x as f32;
            if !o.is_finite() {
                return Err(self.syntax(&first, format!("{what}: number {x} is out of range")));
            }
        }
        Ok(out)
    }

    /// A bracketed array of numbers, or the bare numbers up to the next non-number.
    pub fn number_array(&mut self, what: &str) -> Result<Vec<f64>, ParseError> {
        let mut out = Vec::new();
        if matches!(self.peek_kind()?, TokenKind::LBracket) {
            self.next()?;
            loop {
                let t = self.next()?;
                match t.kind {
                    TokenKind::Num(v) => out.push(v),
                    TokenKind::RBracket => return Ok(out),
                    ref other => {
                        return Err(self.syntax(
                            &t,
                            format!(
                                "{what}: expected a number or `]`, found {}",
                                other.describe()
                            ),
                        ))
                    }
                }
            }
        }
        while let TokenKind::Num(v) = *self.peek_kind()? {
            out.push(v);
            self.next()?;
        }
        Ok(out)
    }

    /// The parameter list that ends a statement.
    pub fn params(&mut self, statement: String) -> Result<ParamList, ParseError> {
        let mut params = Vec::new();
        loop {
            match self.peek_kind()? {
                TokenKind::Ident(_) | TokenKind::Eof => break,
                TokenKind::Str(_) => {}
                other => {
                    let found = other.describe();
                    let t = self.next()?;
                    return Err(self.syntax(
                        &t,
                        format!(
                            "{statement}: expected a parameter declaration (\"type name\") or the next statement, found {found}"
                        ),
                    ));
                }
            }
            let decl = self.next()?;
            let TokenKind::Str(text) = &decl.kind else {
                unreachable!("peeked a string")
            };
            let mut words = text.split_whitespace();
            let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
                return Err(self.syntax(
                    &decl,
                    format!("expected a parameter declaration \"type name\", found \"{text}\""),
                ));
            };
            let Some(ty) = ParamType::from_name(ty) else {
                return Err(self.syntax(
                    &decl,
                    format!("unknown parameter type `{ty}` in \"{text}\" (expected float, integer, bool, point, vector, normal, string, texture or color)"),
                ));
            };
            let name = name.to_string();
            let values = self.values(&statement, &text.clone())?;
            params.push(Param::new(ty, name, values, self.pos(&decl)));
        }
        Ok(ParamList::new(statement, params))
    }

    fn values(&mut self, statement: &str, decl: &str) -> Result<Values, ParseError> {
        let t = self.next()?;
        match t.kind {
            TokenKind::Num(v) => Ok(Values::Numbers(vec![v])),
            TokenKind::Str(s) => Ok(Values::Strings(vec![s.into_owned()])),
            TokenKind::LBracket => {
                let first = self.next()?;
                match first.kind {
                    TokenKind::RBracket => Ok(Values::Numbers(Vec::new())),
                    TokenKind::Num(v) => {
                        let mut out = vec![v];
                        loop {
                            let t = self.next()?;
                            match t.kind {
                                TokenKind::Num(v) => out.push(v),
                                TokenKind::RBracket => return Ok(Values::Numbers(out)),
                                ref other => return Err(self.syntax(
                                    &t,
                                    format!("{statement} \"{decl}\": expected a number or `]`, found {}", other.describe()),
                                )),
                            }
                        }
                    }
                    TokenKind::Str(s) => {
                        let mut out = vec![s.into_owned()];
                        loop {
                            let t = self.next()?;
                            match t.kind {
                                TokenKind::Str(s) => out.push(s.into_owned()),
                                TokenKind::RBracket => return Ok(Values::Strings(out)),
                                ref other => return Err(self.syntax(
                                    &t,
                                    format!("{statement} \"{decl}\": expected a string or `]`, found {}", other.describe()),
                                )),
                            }
                        }
                    }
                    ref other => Err(self.syntax(
                        &first,
                        format!(
                            "{statement} \"{decl}\": expected values, found {}",
                            other.describe()
                        ),
                    )),
                }
            }
            ref other => Err(self.syntax(
                &t,
                format!(
                    "{statement} \"{decl}\": expected a value or `[`, found {}",
                    other.describe()
                ),
            )),
        }
    }
}
