//! User text quoted in error messages. Every reader (measurement CSV, OBJ, PLY, eval geometry CSV,
//! material and scene TOML, weather CSV, times file, `--times` and other flags) quotes the
//! offending text through [`shown`], [`shown_at_most`] or [`parser_message`], and a scene's names
//! pass [`name_problem`] before any message quotes them whole, so that a stray
//! control character (a carriage return, an escape sequence, a NUL) is visible in the message
//! instead of acting on the user's terminal, and a multi-megabyte line cannot become a
//! multi-megabyte message: one message stays one short line.

/// Characters of a quoted value kept before it is cut with '…': enough for any number, column
/// name or keyword a user would recognise, short enough for a one-line message.
pub const SHOWN_CHARS: usize = 40;

/// `text` as it may be quoted in a message: control characters escaped and at most
/// [`SHOWN_CHARS`] characters.
pub fn shown(text: &str) -> String {
    shown_at_most(text, SHOWN_CHARS)
}

/// [`shown`] with another length limit, for longer texts such as a parser's own message.
/// Numerals longer than [`LONG_NUMERAL_CHARS`] are shown as [`number`]s first (a parser's
/// "floating point `0.000…`" of 300 digits becomes "1e-300").
pub fn shown_at_most(text: &str, max_chars: usize) -> String {
    // Numerals are shortened in the part that can be shown (and a margin: a shortened numeral
    // takes fewer characters); one cut by the margin's end is left as it is.
    let margin_end = text
        .char_indices()
        .nth(max_chars.saturating_add(1000))
        .map_or(text.len(), |(i, _)| i);
    let shortened = numerals_shortened(&text[..margin_end], margin_end < text.len());
    escaped_at_most(&shortened, max_chars)
}

/// `text` with control characters escaped, cut after `max_chars` characters with '…'.
fn escaped_at_most(text: &str, max_chars: usize) -> String {
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i == max_chars {
            out.push('…');
            break;
        }
        if is_hidden(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// Characters of a file path kept in a message: a real path fits whole; a longer one keeps its
/// start and its end (the file's name), cut in the middle with '…'.
pub const SHOWN_PATH_CHARS: usize = 160;

/// A file path as a message shows it: control characters escaped and at most
/// [`SHOWN_PATH_CHARS`] characters, its start and its end kept.
pub fn path(path: &std::path::Path) -> String {
    let text = path.to_string_lossy();
    let count = text.chars().count();
    // A path is shown as it is spelt: its numerals are names, not numbers to shorten.
    if count <= SHOWN_PATH_CHARS {
        return escaped_at_most(&text, SHOWN_PATH_CHARS);
    }
    let head: String = text.chars().take(SHOWN_PATH_CHARS / 4).collect();
    let tail: String = text
        .chars()
        .skip(count - SHOWN_PATH_CHARS * 3 / 4)
        .collect();
    format!(
        "{}…{}",
        escaped_at_most(&head, SHOWN_PATH_CHARS),
        escaped_at_most(&tail, SHOWN_PATH_CHARS)
    )
}

/// Significant digits a message shows of a number at most ([`number`]).
pub const NUMBER_DIGITS: usize = 12;

/// A number as a message shows it — the one rule for echoing a user's number: at most
/// [`NUMBER_DIGITS`] significant digits (0.1 + 0.2 shows as 0.3), plainly within
/// 1e-4 ≤ |x| < 1e6 (and 0, NaN, ±inf), in exponent form beyond, where Rust's plain form of
/// 1e308 is 309 digits long.
pub fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let x: f64 = format!("{x:.prec$e}", prec = NUMBER_DIGITS - 1)
        .parse()
        .unwrap_or(x);
    if (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Characters from which a numeral in a quoted text is shown as a [`number`] instead.
pub const LONG_NUMERAL_CHARS: usize = 20;

/// `text` with every numeral (`-1.5e3`, `000123`, `0.000…1`) longer than
/// [`LONG_NUMERAL_CHARS`] characters replaced by its [`number`]; with `cut_at_end`, a numeral
/// reaching the end of `text` is kept (it may go on beyond).
pub fn numerals_shortened(text: &str, cut_at_end: bool) -> std::borrow::Cow<'_, str> {
    let bytes = text.as_bytes();
    let mut out = String::new();
    let (mut copied, mut i) = (0, 0);
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            || (matches!(bytes[i], b'-' | b'+' | b'.')
                && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        let in_word = |b: u8| b.is_ascii_alphanumeric() || b == b'_' || b == b'.';
        if !starts || (i > 0 && in_word(bytes[i - 1])) {
            i += 1;
            continue;
        }
        let end = numeral_end(bytes, i);
        // Digits that run on into a word (a hash, a file name) are not a number.
        let word_follows = bytes
            .get(end)
            .is_some_and(|&b| b.is_ascii_alphanumeric() || b == b'_');
        let reaches_end = end == bytes.len() && cut_at_end;
        if end - i > LONG_NUMERAL_CHARS && !reaches_end && !word_follows {
            // A numeral beyond f64 (1e999, or 1e-999 read as 0) keeps its own spelling: "inf" or
            // "0" would be another value than the one written.
            let numeral = &text[i..end];
            let value = numeral.parse::<f64>().ok().filter(|v| {
                v.is_finite() && (*v != 0.0 || !numeral.bytes().any(|b| matches!(b, b'1'..=b'9')))
            });
            if let Some(value) = value {
                out.push_str(&text[copied..i]);
                out.push_str(&number(value));
                copied = end;
            }
        }
        i = end;
    }
    if copied == 0 {
        return std::borrow::Cow::Borrowed(text);
    }
    out.push_str(&text[copied..]);
    std::borrow::Cow::Owned(out)
}

/// The end of the numeral starting at `start`: sign, digits, fraction, exponent.
fn numeral_end(bytes: &[u8], start: usize) -> usize {
    let digits = |mut i: usize| {
        while bytes.get(i).is_some_and(u8::is_ascii_digit) {
            i += 1;
        }
        i
    };
    let mut i = start + usize::from(matches!(bytes[start], b'-' | b'+'));
    i = digits(i);
    if bytes.get(i) == Some(&b'.') && bytes.get(i + 1).is_some_and(u8::is_ascii_digit) {
        i = digits(i + 1);
    }
    if matches!(bytes.get(i), Some(b'e' | b'E')) {
        let sign = usize::from(matches!(bytes.get(i + 1), Some(b'-' | b'+')));
        if bytes.get(i + 1 + sign).is_some_and(u8::is_ascii_digit) {
            i = digits(i + 1 + sign);
        }
    }
    i
}

/// A large or computed number as a message shows it: [`number`] of it rounded to three
/// significant digits ("7.2e12 steps", not "7.200000000001e12").
pub fn about(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return number(x);
    }
    let rounded: f64 = format!("{x:.2e}").parse().unwrap_or(x);
    number(rounded)
}

/// `value` to `digits` significant digits in plain notation (0.0000061 stays readable as such);
/// in exponent form below ~1e-13 and from 1e15 on, where plain notation would print only zeros
/// or digits that were never there (1e308 is not 309 digits long).
pub fn significant(value: f64, digits: i32) -> String {
    if value == 0.0 || !value.is_finite() {
        return format!("{value}");
    }
    let decimals = digits - 1 - value.abs().log10().floor() as i32;
    if decimals > 15 || value.abs() >= 1e15 {
        // Below ~1e-13 plain notation would print only zeros ("d < 0.000000000000000").
        let mantissa = (digits - 1).max(0) as usize;
        return format!("{value:.mantissa$e}");
    }
    let decimals = decimals.max(0) as usize;
    format!("{value:.decimals$}")
}

/// [`significant`] without trailing zeros (75, 1.064, 1e-300; never "1.00000e-3"): how a
/// message shows a value it lists beside others of the same kind.
pub fn significant_trimmed(value: f64, digits: i32) -> String {
    let text = significant(value, digits);
    let (mantissa, exponent) = match text.find('e') {
        Some(at) => text.split_at(at),
        None => (text.as_str(), ""),
    };
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    format!("{mantissa}{exponent}")
}

/// Longest name (of an object, part, material or layer) a scene may give, in characters: messages
/// quote names whole, so a name stays short enough for a one-line message.
pub const MAX_NAME_CHARS: usize = 100;

/// Why `name` cannot be a name that messages quote whole, if it cannot: it holds a control
/// character or is longer than [`MAX_NAME_CHARS`]. The reason quotes it through [`shown`].
pub fn name_problem(name: &str) -> Option<String> {
    if name.chars().any(is_hidden) {
        return Some(format!("'{}' contains a control character", shown(name)));
    }
    let count = name.chars().count();
    (count > MAX_NAME_CHARS).then(|| {
        format!(
            "'{}' is {count} characters long; at most {MAX_NAME_CHARS}",
            shown(name)
        )
    })
}

/// A parser's message as one short line: runs of whitespace (its line breaks) as one space,
/// control characters escaped, at most `max_chars` characters.
pub fn parser_message(message: &str, max_chars: usize) -> String {
    let joined = message.split_whitespace().collect::<Vec<_>>().join(" ");
    shown_at_most(&joined, max_chars)
}

/// Characters that a terminal acts on or that reorder the text around them: C0/C1 controls and
/// the Unicode bidirectional marks, embeddings, overrides and isolates.
fn is_hidden(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{200E}' | '\u{200F}' | '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}')
}

/// `count` and `noun`, plural unless one: "1 row", "12 rows".
pub fn counted(count: usize, noun: &str) -> String {
    if count == 1 {
        format!("1 {noun}")
    } else {
        format!("{count} {noun}s")
    }
}

/// `45 s`, `12 min`, `13 h`, `3.2 days`.
pub fn duration(seconds: f64) -> String {
    if seconds < 120.0 {
        format!("{} s", about(seconds))
    } else if seconds < 7200.0 {
        format!("{} min", about(seconds / 60.0))
    } else if seconds < 3.0 * 86_400.0 {
        format!("{} h", about(seconds / 3600.0))
    } else {
        format!("{} days", about(seconds / 86_400.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_in_their_unit() {
        assert_eq!(duration(45.0), "45 s");
        assert_eq!(duration(720.0), "12 min");
        assert_eq!(duration(13.0 * 3600.0), "13 h");
        assert_eq!(duration(3.2 * 86_400.0), "3.2 days");
    }

    #[test]
    fn controls_are_escaped_and_long_text_is_cut() {
        assert_eq!(shown("a\rb\u{1b}[31m\0"), "a\\rb\\u{1b}[31m\\u{0}");
        assert_eq!(shown("x\u{202E}y"), "x\\u{202e}y");
        let long = "é".repeat(1000);
        assert_eq!(shown(&long), format!("{}…", "é".repeat(SHOWN_CHARS)));
        assert_eq!(shown_at_most("abcdef", 3), "abc…");
        assert_eq!(shown("plain, text"), "plain, text");
        assert_eq!(number(1e308), "1e308");
        assert_eq!(significant(6.1e-6, 2), "0.0000061");
        assert_eq!(significant(3.2e-17, 3), "3.20e-17");
        let deep = std::path::PathBuf::from(format!("data/{}/m\u{1b}.csv", "d".repeat(500)));
        let cut = path(&deep);
        assert!(
            cut.starts_with("data/dd") && cut.ends_with("d/m\\u{1b}.csv"),
            "{cut}"
        );
        assert!(cut.chars().count() < SHOWN_PATH_CHARS + 20, "{cut}");
        assert_eq!(
            path(std::path::Path::new("fits/paint.toml")),
            "fits/paint.toml"
        );
        let digits = format!("data/{}.csv", "1".repeat(30));
        assert_eq!(path(std::path::Path::new(&digits)), digits);
        assert_eq!(number(-1e-300), "-1e-300");
        assert_eq!(number(-0.1), "-0.1");
        assert_eq!(number(f64::NAN), "NaN");
        assert_eq!(number(2.0), "2");
        assert_eq!(about(7.200000000001e12), "7.2e12");
        assert_eq!(about(123456.7), "123000");
        assert_eq!(about(-0.000123456), "-0.000123");
    }

    /// One rule for a user's number in a message (issue 42): at most 12 significant digits, the
    /// exponent kept, whatever its size; long numerals in parsers' messages shown the same way.
    #[test]
    fn numbers_keep_twelve_digits_and_their_exponent() {
        assert_eq!(number(0.1 + 0.2), "0.3");
        assert_eq!(number(1e308), "1e308");
        assert_eq!(number(1.2345678901234567e-300), "1.23456789012e-300");
        assert_eq!(number(123456.78901234567), "123456.789012");
        assert_eq!(number(f64::MAX), "1.79769313486e308");
        assert_eq!(significant(1e308, 6), "1.00000e308");
        assert_eq!(significant_trimmed(1e308, 6), "1e308");
        assert_eq!(significant_trimmed(1e-300, 6), "1e-300");
        assert_eq!(significant_trimmed(1.064, 6), "1.064");
        assert_eq!(significant_trimmed(75.0, 6), "75");
        let zeros = format!(
            "invalid type: floating point `0.{}1`, expected u64",
            "0".repeat(299)
        );
        assert_eq!(
            shown_at_most(&zeros, 200),
            "invalid type: floating point `1e-300`, expected u64"
        );
        let big = format!(
            "invalid latitude 1{}.0 at 2026-06-21T10:00:00Z",
            "0".repeat(308)
        );
        assert_eq!(
            shown_at_most(&big, 200),
            "invalid latitude 1e308 at 2026-06-21T10:00:00Z"
        );
        let ends = format!("latitude -1{}.", "0".repeat(30));
        assert_eq!(shown_at_most(&ends, 200), "latitude -1e30.");
        // Short numerals, dates and words with digits stay as written.
        assert_eq!(shown("0.100000000000000005"), "0.100000000000000005");
        assert_eq!(shown("m00 2026-06-21 abc123"), "m00 2026-06-21 abc123");
        let hash = format!("{}ab _{}", "1".repeat(25), "2".repeat(25));
        assert_eq!(shown_at_most(&hash, 100), hash);
        // Numerals beyond f64 are not shown as inf or 0.
        let huge = format!("x {} y", "9".repeat(400));
        assert_eq!(shown_at_most(&huge, 1000), huge);
        let tiny = format!("x 0.{}1 y", "0".repeat(400));
        assert_eq!(shown_at_most(&tiny, 1000), tiny);
        assert_eq!(shown_at_most(&"0".repeat(30), 100), "0");
        // A numeral cut by the text's end is not shortened into another value.
        let cut = "9".repeat(5000);
        assert!(shown(&cut).starts_with("9999"), "{}", shown(&cut));
    }

    #[test]
    fn names_are_short_and_printable_and_parser_messages_one_short_line() {
        assert_eq!(name_problem("hood"), None);
        assert_eq!(name_problem(&"é".repeat(MAX_NAME_CHARS)), None);
        let long = name_problem(&"n".repeat(101)).unwrap();
        assert!(
            long.ends_with("is 101 characters long; at most 100"),
            "{long}"
        );
        assert_eq!(
            name_problem("a\u{1e}b").unwrap(),
            "'a\\u{1e}b' contains a control character"
        );
        assert_eq!(
            parser_message("unknown\n  field `x\u{1b}`", 100),
            "unknown field `x\\u{1b}`"
        );
        assert_eq!(parser_message(&"x ".repeat(500), 10), "x x x x x …");
    }
}
