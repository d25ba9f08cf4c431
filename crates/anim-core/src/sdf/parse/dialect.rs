//! Spellings that other readers of the language take and the statements do not know, turned
//! into the canonical tokens before a line is read (docs/scene-language.md §1, "Dialects"):
//! numbers glued by a sign, the German `dreieck`, and template placeholders, which no reading
//! can give a value.

use super::{lenient_number, At, Parser};
use crate::sdf::lexer::{parse_number, Line, Token};

impl Parser<'_> {
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
        for (i, t) in out.tokens.iter().enumerate() {
            let between_numbers = |j: Option<usize>| {
                j.and_then(|j| out.tokens.get(j))
                    .is_some_and(|n| lenient_number(n.text).is_some())
            };
            let in_numbers = between_numbers(i.checked_sub(1)) || between_numbers(Some(i + 1));
            match split_glued(t) {
                Some(parts) if in_numbers && !is_name_position(&out.tokens, i) => {
                    if glued.is_none() {
                        let texts: Vec<&str> = parts.iter().map(|p| p.text).collect();
                        glued = Some((i, t.text, texts));
                    }
                    tokens.extend(parts);
                }
                _ => tokens.push(*t),
            }
        }
        if let Some((i, text, parts)) = glued {
            self.variant(
                line,
                At::Tok(i),
                "glued numbers",
                format!(
                    "`{text}` read as {} numbers, `{}`, as a C++ stream reader reads it",
                    parts.len(),
                    parts.join("` `")
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
/// cut before each sign that does not follow an exponent's `e`, all are. `None` otherwise.
fn split_glued<'t>(t: &Token<'t>) -> Option<Vec<Token<'t>>> {
    let text = t.text;
    if lenient_number(text).is_some() || !text.is_ascii() {
        return None;
    }
    let bytes = text.as_bytes();
    let mut cuts: Vec<usize> = (1..bytes.len())
        .filter(|&j| matches!(bytes[j], b'+' | b'-') && !matches!(bytes[j - 1], b'e' | b'E'))
        .collect();
    if cuts.is_empty() {
        return None;
    }
    cuts.insert(0, 0);
    cuts.push(bytes.len());
    let parts: Vec<Token<'t>> = cuts
        .windows(2)
        .map(|w| Token {
            text: &text[w[0]..w[1]],
            col: t.col + w[0] as u32,
            width: (w[1] - w[0]) as u32,
        })
        .collect();
    parts
        .iter()
        .all(|p| parse_number(p.text).is_ok())
        .then_some(parts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn token(text: &str) -> Token<'_> {
        Token {
            text,
            col: 10,
            width: text.len() as u32,
        }
    }

    fn split(text: &str) -> Option<Vec<(String, u32)>> {
        split_glued(&token(text)).map(|p| p.iter().map(|t| (t.text.to_string(), t.col)).collect())
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
