//! pbrt-v4's tokens (its `Tokenizer`, parser.cpp): quoted strings (with `\"`, `\\`, `\n`,
//! `\t` escapes), `[` and `]`, `#` comments to the end of the line, and bare words (directive
//! names, numbers, `true`/`false`), each with the line and column it starts at.

use super::Loc;
use foton_core::error::Result;
use std::path::Path;
use std::rc::Rc;

#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// A quoted string, unescaped.
    Str(String),
    /// A bare word: a directive, a number, `true` or `false`.
    Word(String),
    Open,
    Close,
}

#[derive(Clone, Debug)]
pub struct Token {
    pub tok: Tok,
    pub loc: Loc,
}

impl Token {
    /// The token as the file wrote it, for messages.
    pub fn shown(&self) -> String {
        match &self.tok {
            Tok::Str(s) => format!("{s:?}"),
            Tok::Word(w) => format!("`{w}`"),
            Tok::Open => "`[`".into(),
            Tok::Close => "`]`".into(),
        }
    }
}

/// The tokens of `text`, the content of `file`.
pub fn tokenize(file: &Rc<Path>, text: &str) -> Result<Vec<Token>> {
    let mut tokens = Vec::new();
    let mut chars = text.chars().peekable();
    let (mut line, mut column) = (1u32, 1u32);
    let loc = |line, column| Loc {
        file: file.clone(),
        line,
        column,
    };
    while let Some(&c) = chars.peek() {
        let start = loc(line, column);
        let mut advance = |chars: &mut std::iter::Peekable<std::str::Chars<'_>>| {
            let c = chars.next();
            if c == Some('\n') {
                line += 1;
                column = 1;
            } else {
                column += 1;
            }
            c
        };
        match c {
            ' ' | '\t' | '\r' | '\n' => {
                advance(&mut chars);
            }
            '#' => {
                while chars.peek().is_some_and(|&c| c != '\n') {
                    advance(&mut chars);
                }
            }
            '[' | ']' => {
                advance(&mut chars);
                let tok = if c == '[' { Tok::Open } else { Tok::Close };
                tokens.push(Token { tok, loc: start });
            }
            '"' => {
                advance(&mut chars);
                let mut s = String::new();
                loop {
                    match advance(&mut chars) {
                        None | Some('\n') => {
                            return Err(start.error(
                                "syntax",
                                "unterminated string: expected a closing `\"` on the same line",
                            ));
                        }
                        Some('"') => break,
                        Some('\\') => match advance(&mut chars) {
                            Some('n') => s.push('\n'),
                            Some('t') => s.push('\t'),
                            Some('b') => s.push('\u{8}'),
                            Some('f') => s.push('\u{c}'),
                            Some('r') => s.push('\r'),
                            Some(c @ ('"' | '\\' | '\'')) => s.push(c),
                            Some(other) => {
                                return Err(loc(line, column - 1).error(
                                    "syntax",
                                    format!("unknown escape `\\{other}` in a string"),
                                ));
                            }
                            None => {
                                return Err(start.error(
                                    "syntax",
                                    "unterminated string: expected a closing `\"`",
                                ));
                            }
                        },
                        Some(c) => s.push(c),
                    }
                }
                tokens.push(Token {
                    tok: Tok::Str(s),
                    loc: start,
                });
            }
            _ => {
                let mut w = String::new();
                while let Some(&c) = chars.peek() {
                    if c.is_whitespace() || matches!(c, '"' | '[' | ']' | '#') {
                        break;
                    }
                    w.push(c);
                    advance(&mut chars);
                }
                tokens.push(Token {
                    tok: Tok::Word(w),
                    loc: start,
                });
            }
        }
    }
    Ok(tokens)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(text: &str) -> Result<Vec<(Tok, u32, u32)>> {
        let file: Rc<Path> = Rc::from(Path::new("t.pbrt"));
        Ok(tokenize(&file, text)?
            .into_iter()
            .map(|t| (t.tok, t.loc.line, t.loc.column))
            .collect())
    }

    #[test]
    fn tokens_with_their_places() {
        let t = toks("Shape \"sphere\" # a comment\n  \"float radius\" [ 2.5 ]\n").unwrap();
        assert_eq!(
            t,
            vec![
                (Tok::Word("Shape".into()), 1, 1),
                (Tok::Str("sphere".into()), 1, 7),
                (Tok::Str("float radius".into()), 2, 3),
                (Tok::Open, 2, 18),
                (Tok::Word("2.5".into()), 2, 20),
                (Tok::Close, 2, 24),
            ]
        );
    }

    #[test]
    fn escapes_and_adjacent_brackets() {
        let t = toks("\"a\\\"b\"[1]").unwrap();
        assert_eq!(t[0].0, Tok::Str("a\"b".into()));
        assert_eq!(t[1].0, Tok::Open);
        assert_eq!(t[2].0, Tok::Word("1".into()));
        assert_eq!(t[3].0, Tok::Close);
    }

    #[test]
    fn unterminated_string_is_an_error_at_its_start() {
        let e = toks("Shape\n  \"sphere\n").unwrap_err().to_string();
        assert!(e.contains("t.pbrt:2:3"), "{e}");
        assert!(e.contains("unterminated string"), "{e}");
    }
}
