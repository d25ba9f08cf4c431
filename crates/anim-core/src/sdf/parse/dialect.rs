//! Spellings that other readers of the language take and the statements do not know, turned
//! into the canonical tokens before a line is read (docs/scene-language.md §1, "Dialects"):
//! numbers glued by a sign, a number glued to the next statement's first word, the German
//! `dreieck`, and template placeholders, which no reading can give a value.

use super::{lenient_number, At, Parser};
use crate::sdf::lexer::{parse_number, Line, Token};

/// The words a statement starts with: where a number runs into one of them, a C++ stream
/// reader (`file >> x`) has read the number and goes on with a new statement.
const STATEMENT_STARTS: [&str; 10] = [
    "define",
    "transform",
    "view",
    "render",
    "renderer",
    "camera",
    "ambient",
    "background",
    "motion",
    "include",
];

/// The length of the number that token `t` starts with, when the rest of it is the first
/// word of a statement (`0.70ambient`).
fn glued_start(t: &Token) -> Option<usize> {
    if !may_be_glued(t) {
        return None;
    }
    STATEMENT_STARTS.iter().find_map(|word| {
        let number = t.text.strip_suffix(word)?;
        (!number.is_empty() && parse_number(number).is_ok()).then_some(number.len())
    })
}

/// Whether token `t` starts like a number and ends like a word: the byte test that every
/// token of every line passes through, so that the rest is asked of almost none.
#[inline]
fn may_be_glued(t: &Token) -> bool {
    let b = t.text.as_bytes();
    b.first()
        .is_some_and(|c| c.is_ascii_digit() || matches!(c, b'.' | b'-' | b'+'))
        && b.last().is_some_and(u8::is_ascii_lowercase)
}

impl Parser<'_> {
    /// The statements of a line on which a number runs into the first word of the next
    /// statement (`… 0.70ambient 0.2 …`), cut there as a C++ stream reader reads it: the
    /// number ends one statement and the word starts the next, with a warning the first time.
    /// `None` when no number does (almost every line: nothing is copied).
    pub(super) fn split_statements<'t>(&mut self, line: &Line<'t>) -> Option<Vec<Line<'t>>> {
        let glued = |tokens: &[Token], i: usize| {
            (i > 0 && may_be_glued(&tokens[i]) && !is_name_position(tokens, i))
                .then(|| glued_start(&tokens[i]))
                .flatten()
        };
        let first = (0..line.tokens.len()).find(|&i| glued(&line.tokens, i).is_some())?;
        let mut statements = Vec::new();
        let mut current: Vec<Token<'t>> = Vec::new();
        for (i, t) in line.tokens.iter().enumerate() {
            let at = current.len();
            current.push(*t);
            let Some(len) = (i >= first).then(|| glued(&current, at)).flatten() else {
                continue;
            };
            current[at] = Token {
                text: &t.text[..len],
                col: t.col,
                width: len as u32,
            };
            if i == first {
                self.variant(
                    line,
                    At::Tok(i),
                    "glued statement",
                    format!(
                        "`{}` read as the number `{}` and then a new statement from `{}`, as a C++ stream reader reads it",
                        t.text,
                        &t.text[..len],
                        &t.text[len..]
                    ),
                    "a number runs into the next statement's first word; start each statement on a line of its own"
                        .into(),
                );
            }
            let ended = std::mem::take(&mut current);
            statements.push(Line {
                number: line.number,
                text: line.text,
                tokens: ended,
            });
            current.push(Token {
                text: &t.text[len..],
                col: t.col + len as u32,
                width: t.width - len as u32,
            });
        }
        statements.push(Line {
            number: line.number,
            text: line.text,
            tokens: current,
        });
        Some(statements)
    }

    /// The line as the statement readers take it; `None` (with the error reported) when it
    /// cannot be read at all.
    pub(super) fn normalise<'t>(&mut self, line: &Line<'t>) -> Option<Line<'t>> {
        if let Some(i) = line.tokens.iter().position(|t| t.text.contains("{{")) {
            // The placeholder may be written with spaces inside, `{{ NAME }}`: it runs to the
            // token that closes it (or to the end of its own token when none does).
            let close = (i..line.tokens.len())
                .find(|&j| {
                    let t = line.tokens[j].text;
                    let from = if j == i {
                        t.find("{{").map_or(0, |s| s + 2)
                    } else {
                        0
                    };
                    t[from..].contains("}}")
                })
                .unwrap_or(i);
            let words: Vec<&str> = line.tokens[i..=close].iter().map(|t| t.text).collect();
            let joined = words.join(" ");
            let start = joined.find("{{").unwrap_or(0);
            let end = joined
                .rfind("}}")
                .filter(|&e| e >= start + 2)
                .map_or(joined.len(), |e| e + 2);
            self.error(
                line,
                At::Span(i, close),
                format!(
                    "`{}` is a template placeholder: this file is a template that another program fills in before anything renders it",
                    &joined[start..end]
                ),
                Some("render the files that program writes, not the template".into()),
            );
            return None;
        }
        let mut out = line.clone();
        if let Some(k) = german_kind(&out.tokens) {
            out.tokens[k].text = "triangle";
            self.variant(
                line,
                At::Tok(k),
                "dreieck",
                "`dreieck` read as `triangle`".into(),
                "the German name of the shape; anim's is `triangle`".into(),
            );
        }
        let mut glued = None;
        let mut tokens = Vec::with_capacity(out.tokens.len());
        // Pieces of glued numbers count against the tokens a line may hold.
        let mut room = crate::limits::MAX_TOKENS_PER_LINE.saturating_sub(out.tokens.len());
        for (i, t) in out.tokens.iter().enumerate() {
            let between_numbers = |j: Option<usize>| {
                j.and_then(|j| out.tokens.get(j))
                    .is_some_and(|n| lenient_number(n.text).is_some())
            };
            let in_numbers = between_numbers(i.checked_sub(1)) || between_numbers(Some(i + 1));
            let split = (in_numbers && !is_name_position(&out.tokens, i))
                .then(|| split_glued(t, room + 1))
                .flatten();
            match split {
                Some(parts) => {
                    room -= parts.len() - 1;
                    if glued.is_none() {
                        let texts: Vec<&str> = parts.iter().take(8).map(|p| p.text).collect();
                        glued = Some((i, t.text, parts.len(), texts));
                    }
                    tokens.extend(parts);
                }
                None => tokens.push(*t),
            }
        }
        if let Some((i, text, count, first)) = glued {
            let more = if count > first.len() { " …" } else { "" };
            self.variant(
                line,
                At::Tok(i),
                "glued numbers",
                format!(
                    "`{}` read as {count} numbers, `{}`{more}, as a C++ stream reader reads it",
                    crate::diag::shorten(text),
                    first.join("` `")
                ),
                "numbers run together where a sign starts the next one; put a space between them"
                    .into(),
            );
            out.tokens = tokens;
        }
        Some(out)
    }
}

/// Whether [`Parser::normalise`] may change the line: a cheap look at its bytes, as almost no
/// line needs it.
pub(super) fn may_need_normalising(line: &Line) -> bool {
    // A placeholder's brace, or a sign glued to a number before it (after a digit or a
    // decimal point). Every line of a file passes here, so its bytes are looked at eight at
    // a time, and each sign found (negative numbers have many) is looked at alone.
    let bytes = line.text.as_bytes();
    let suspicious = |k: usize| {
        bytes[k] == b'{'
            || (k > 0 && matches!(bytes[k], b'-' | b'+') && {
                let before = bytes[k - 1];
                before.is_ascii_digit() || before == b'.'
            })
    };
    let mut chunks = bytes.chunks_exact(8);
    for (n, chunk) in chunks.by_ref().enumerate() {
        let mut v = [0u8; 8];
        v.copy_from_slice(chunk);
        let v = u64::from_le_bytes(v);
        let mut hits = byte_mask(v, b'-') | byte_mask(v, b'+') | byte_mask(v, b'{');
        while hits != 0 {
            if suspicious(n * 8 + (hits.trailing_zeros() / 8) as usize) {
                return true;
            }
            hits &= hits - 1;
        }
    }
    let tail = bytes.len() - chunks.remainder().len();
    (tail..bytes.len()).any(suspicious) || german_kind(&line.tokens).is_some()
}

/// The high bit of each byte of `v` that may equal `byte`: every byte that does, and
/// possibly some after one that does (the borrow of the subtraction), which the caller
/// looks at again.
fn byte_mask(v: u64, byte: u8) -> u64 {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGHS: u64 = 0x8080_8080_8080_8080;
    let x = v ^ (ONES * u64::from(byte));
    x.wrapping_sub(ONES) & !x & HIGHS
}

/// Where a line written `define shape dreieck` or `define dreieck` names its kind in German.
fn german_kind(tokens: &[Token]) -> Option<usize> {
    let word = |i: usize| tokens.get(i).map_or("", |t| t.text);
    if word(0) != "define" {
        return None;
    }
    match (word(1), word(2)) {
        ("shape", "dreieck") => Some(2),
        ("dreieck", _) => Some(1),
        _ => None,
    }
}

/// Whether token `i` is where a statement writes a name (which may look like anything).
fn is_name_position(tokens: &[Token], i: usize) -> bool {
    let first = tokens.first().map_or("", |t| t.text);
    let second = tokens.get(1).map_or("", |t| t.text);
    match first {
        "define" if second == "shape" => i <= 3,
        "define" => i <= 2,
        _ => i <= 1,
    }
}

/// `1000-300` as the tokens `1000` and `-300`: a word that is no number but whose pieces,
/// cut before each sign that does not follow an exponent's `e`, all are. `None` otherwise,
/// and when it would make more than `room` tokens (the line's token cap): the pieces are
/// checked before any is kept, so a word of megabytes that is no run of numbers costs no
/// memory, and one that is costs at most the cap.
fn split_glued<'t>(t: &Token<'t>, room: usize) -> Option<Vec<Token<'t>>> {
    let text = t.text;
    if !text.is_ascii() || lenient_number(text).is_some() {
        return None;
    }
    let mut count = 0usize;
    for piece in glued_pieces(text) {
        count += 1;
        if count > room || parse_number(&text[piece]).is_err() {
            return None;
        }
    }
    (count > 1).then(|| {
        glued_pieces(text)
            .map(|piece| Token {
                text: &text[piece.clone()],
                col: t.col + piece.start as u32,
                width: piece.len() as u32,
            })
            .collect()
    })
}

/// The byte ranges of `text` (ASCII) cut before each sign that does not follow an
/// exponent's `e`.
fn glued_pieces(text: &str) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    let bytes = text.as_bytes();
    let mut start = 0;
    std::iter::from_fn(move || {
        if start >= bytes.len() {
            return None;
        }
        let end = (start + 1..bytes.len())
            .find(|&j| matches!(bytes[j], b'+' | b'-') && !matches!(bytes[j - 1], b'e' | b'E'))
            .unwrap_or(bytes.len());
        let piece = start..end;
        start = end;
        Some(piece)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn token(text: &str) -> Token<'_> {
        Token {
            text,
            col: 10,
            width: text.len() as u32,
        }
    }

    fn split(text: &str) -> Option<Vec<(String, u32)>> {
        split_glued(&token(text), usize::MAX)
            .map(|p| p.iter().map(|t| (t.text.to_string(), t.col)).collect())
    }

    #[test]
    fn lines_that_may_need_normalising_are_all_found() {
        let needs = |text: &str| {
            let line = Line {
                number: 1,
                text,
                tokens: crate::sdf::lexer::tokenize(text),
            };
            may_need_normalising(&line)
        };
        for yes in [
            "define shape box b -100 -80 -200 1000-300 80 -100 red",
            "transform egg rotate {{ANGLE_0}} 0 0 1",
            "1.+2",
            "define shape dreieck t 0 0 0 1 0 0 0 1 0 red",
            "define dreieck t 0 0 0 1 0 0 0 1 0 red",
        ] {
            assert!(needs(yes), "{yes}");
        }
        for no in [
            "define shape sphere s0 -43.876 24.320 -68.347 0.0938 mirror",
            "define material m 1e-3 1E+2 .5 -1 +2 -.5 1 1 1 10",
            "define shape sphere my-ball 0 0 -5 1 red-2",
        ] {
            assert!(!needs(no), "{no}");
        }
    }

    #[test]
    fn a_number_runs_into_the_next_statement_only_where_a_statement_word_follows_it() {
        let text = "define material m 1 0 0 1 0 0 1 0 0 10ambient 0.1 0.1 0.1background 0 0 1\n\
                    define camera 2camera 60\n\
                    define material 5define 1 0 0 1 0 0 1 0 0 10\n";
        let opts = crate::sdf::LoadOptions::default();
        let (statements, diagnostics) = crate::sdf::parse(text, Path::new("s.sdf"), &opts);
        let kinds: Vec<String> = statements
            .iter()
            .map(|s| format!("{}:{}", s.loc.line, s.loc.col))
            .collect();
        // Material, ambient (just after `10`), background (just after the last `0.1`); the
        // camera and the material named like a glued statement are names, left whole.
        assert_eq!(
            kinds,
            ["1:1", "1:39", "1:58", "2:1", "3:1"],
            "{diagnostics:?}"
        );
        let warned: Vec<&str> = diagnostics.iter().map(|d| d.message.as_str()).collect();
        assert_eq!(warned.len(), 1, "{warned:?}");
        assert!(warned[0].starts_with("`10ambient` read as the number `10`"));
    }

    #[test]
    fn glued_numbers_split_where_a_stream_reader_stops() {
        assert_eq!(
            split("1000-300"),
            Some(vec![("1000".into(), 10), ("-300".into(), 14)])
        );
        assert_eq!(
            split("1.5+2-.5"),
            Some(vec![
                ("1.5".into(), 10),
                ("+2".into(), 13),
                ("-.5".into(), 15)
            ])
        );
        assert_eq!(
            split("-1e-3-2"),
            Some(vec![("-1e-3".into(), 10), ("-2".into(), 15)])
        );
        // One number, a name, a word with a sign that is no number: left alone.
        for whole in ["1e-3", "-4", "red-2", "a-b", "1-", "--1", "1.0f"] {
            assert_eq!(split(whole), None, "{whole}");
        }
    }
}
