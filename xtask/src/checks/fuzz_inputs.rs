//! The inputs of `cargo xtask fuzz`: random bytes and token soups, and valid files (the seeds)
//! broken the ways files break: cells deleted, duplicated and swapped; huge numbers, NaN and
//! infinities; long lines and long runs; deep nesting; bytes that are not UTF-8; truncation;
//! another separator or decimal mark. Each input is drawn from the run's seed, the reader and
//! the case number alone, so that any case can be made again on its own (`--dump`).

use super::fuzz_seeds::{Reader, Seed};
use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// One generated input.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// The seed it was made from (random inputs too name one: its reading options).
    pub seed: usize,
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// The `--columns` argument (CSV only).
    pub columns: Option<String>,
}

/// Largest input, bytes: long enough for 100,000-column headers and thousands of repeated rows,
/// small enough that a reader's time on it says something about the reader, not about the size.
const MAX_LEN: usize = 4 << 20;

/// Numbers that break naive parsers: not finite, beyond f64 or usize, subnormal, other notations.
const NUMBERS: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "+Infinity",
    "1e309",
    "-1e309",
    "1e308",
    "-1e308",
    "1e-320",
    "5e-324",
    "-0",
    "0",
    "-1",
    "99999999999999999999999",
    "18446744073709551616",
    "4294967296",
    "1e5",
    "0x1F",
    "1_0",
    "1.5.5",
    "",
    ".",
    "-",
    "e5",
    "1,5",
    "+",
    "1e",
    "00000000000000000000001",
    "0.5e-5",
];

/// Words each reader's format gives a meaning to, and some it must refuse.
fn words(reader: Reader) -> &'static [&'static str] {
    match reader {
        Reader::Csv => &[
            "q99999999999_rad",
            "tau900000000_nm",
            "q900000000_rad",
            "q18446744073709551616_rad",
            "q0_rad",
            "q01_rad",
            "q7_rad",
            "q1_mm",
            "q1_m",
            "q1_deg",
            "tau0_nm",
            "tau7_nm",
            "x_mm",
            "x_m",
            "qw",
            "qx",
            "rx_deg",
            "rz_rad",
            "tool",
            "payload_kg",
            "temp_c",
            "t_s",
            "\"\"",
            "\"a,b\"",
            "\"",
            "\u{feff}",
        ],
        Reader::Robot => &[
            "NaN",
            "inf",
            "None",
            "Some(",
            "()",
            "[]",
            "Standard",
            "Modified",
            "Prismatic",
            "Revolute",
            "joints",
            "dh",
            "flange",
            "tool",
            "dynamics",
            "limits_m",
            "1e309",
            "nan nan nan",
            "1e309 0 0",
            "0 0 0",
            "continuous",
            "fixed",
            "floating",
            "<link name=\"x\"/>",
            "</joint>",
            "<joint name=\"j\" type=\"revolute\">",
            "&amp;",
            "&#0;",
            "xacro:macro",
        ],
        Reader::Model => &[
            "NaN",
            "inf",
            "None",
            "Some(",
            "()",
            "[]",
            "schema_version",
            "PoeGpLoad",
            "PoeGp",
            "BaseTool",
            "residual_gp",
            "compensation",
            "joint_compliance",
            "terms",
            "theta",
            "tools",
            "Prismatic",
            "1e309",
            "18446744073709551615",
        ],
        Reader::EffectsList => &[
            "joint_compliance",
            "gear_periodic",
            "backlash",
            "thermal",
            "time_drift",
            "auto",
            ":",
            ",",
            "0",
            "257",
            "18446744073709551616",
            "-1",
            " ",
        ],
        Reader::Options => &[
            "NaN",
            "inf",
            "-inf",
            "0",
            "-1",
            "None",
            "Some(",
            "identification",
            "compensation",
            "effects",
            "selection",
            "prior_sigma",
            "max_iterations",
            "LevenbergMarquardt",
            "PseudoInverse",
            "\"auto\"",
            "\"gear_periodic:1:999\"",
            "18446744073709551615",
        ],
        Reader::Effects => &[
            "NaN",
            "inf",
            "None",
            "Some(",
            "()",
            "[]",
            "compliance",
            "backlash",
            "periodic",
            "thermal",
            "drift",
            "tracker_noise",
            "coupling",
            "harmonics",
            "joint_index",
            "source_joint_index",
            "fixed_point_iterations",
            "1000000000000",
            "18446744073709551615",
        ],
    }
}

/// Nesting openers, repeated thousands of times: a recursive parser's stack.
const OPENERS: &[&str] = &["(", "[", "{", "<a>", "Some(", "\""];

/// Bytes that are not UTF-8 (a lone continuation, a truncated sequence, a surrogate, an overlong).
const INVALID_UTF8: &[&[u8]] = &[b"\xff", b"\x80", b"\xc3", b"\xed\xa0\x80", b"\xc0\xaf", b"\xf4\x90\x80\x80"];

/// The rng of one case: a function of the run's seed, the reader and the case number only.
fn case_rng(run_seed: u64, reader: Reader, case: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(run_seed);
    rng.set_stream(Reader::ALL.iter().position(|r| *r == reader).unwrap_or(0) as u64);
    // 2^20 words per case: far more than one case draws, so that cases never share words.
    rng.set_word_pos(u128::from(case) << 20);
    rng
}

/// Inputs that once crashed, hung or exhausted a reader, each made again exactly: the first cases
/// of every run, so that even a short run (CI) guards against their return.
pub fn regressions(seeds: &[Seed], reader: Reader) -> Vec<Case> {
    let seed_with = |extension: &str| seeds.iter().position(|s| s.extension == extension).unwrap_or(0);
    let case = |seed: usize, text: String| Case { seed, bytes: text.into_bytes(), columns: None };
    let spec = "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,x_mm,y_mm,z_mm";
    let row = "0.1,0.2,0.3,0.4,0.5,0.6,1000,20,1500";
    match reader {
        Reader::Csv => vec![
            // 400,000 columns: every name was compared with every earlier one (minutes).
            case(0, format!("{spec}{}\n{row}{}\n", distinct(",c", "", 400_000), ",0".repeat(400_000))),
            // 80,000 rows, each another tool: each tool name was looked up in a list.
            case(0, format!("{spec},tool\n{}", distinct(&format!("{row},t"), "\n", 80_000))),
            // A joint number used as a size: 2.4 TB allocated before the joint count was checked.
            case(0, format!("q99999999999_rad,{spec}\n0,{row}\n")),
            case(0, format!("{spec},tau900000000_nm\n{row},1\n")),
        ],
        Reader::Robot => vec![
            // 200,000 nested elements: a stack overflow (abort) in the URDF outline.
            case(
                seed_with("urdf"),
                format!("<robot name=\"r\">{}{}</robot>", "<a>".repeat(200_000), "</a>".repeat(200_000)),
            ),
            // 150,000 attributes and 60,000 links: quadratic scans of the attributes and the links.
            case(seed_with("urdf"), format!("<robot name=\"r\"><link{}/></robot>", distinct(" a", "=\"\"", 150_000))),
            case(
                seed_with("urdf"),
                format!("<robot name=\"r\">{}</robot>", distinct("<link name=\"l", "\"/>", 60_000)),
            ),
            case(
                seed_with("ron"),
                format!("Robot(name: \"r\", joints: {}{})", "[".repeat(200_000), "]".repeat(200_000)),
            ),
        ],
        Reader::Model => vec![case(0, format!("({}{})", "(".repeat(200_000), ")".repeat(200_000)))],
        Reader::EffectsList | Reader::Options => vec![],
        Reader::Effects => vec![
            // Each compliance step costs a gravity-torque evaluation: 1e12 of them ran for ever.
            case(0, "(compliance: (fixed_point_iterations: 1000000000000))".into()),
            case(0, format!("(periodic: (harmonics: {}{}))", "[".repeat(200_000), "]".repeat(200_000))),
        ],
    }
}

/// `prefix0 suffix prefix1 suffix …`: `count` distinct items.
fn distinct(prefix: &str, suffix: &str, count: usize) -> String {
    (0..count).map(|i| format!("{prefix}{i}{suffix}")).collect()
}

/// The input `case` of a run: one of the `regressions` first, then random inputs.
pub fn generate(seeds: &[Seed], regressions: &[Case], reader: Reader, run_seed: u64, case: u64) -> Case {
    if let Some(regression) = usize::try_from(case).ok().and_then(|k| regressions.get(k)) {
        return regression.clone();
    }
    let mut rng = case_rng(run_seed, reader, case);
    let seed = rng.random_range(0..seeds.len());
    let original = &seeds[seed];
    let bytes = match rng.random_range(0..20) {
        0 => (0..rng.random_range(0..4096)).map(|_| rng.random()).collect(),
        1 => token_soup(&original.bytes, reader, &mut rng),
        _ => {
            let mut bytes = original.bytes.clone();
            for _ in 0..mutation_count(&mut rng) {
                mutate(&mut bytes, reader, &mut rng);
                bytes.truncate(MAX_LEN);
            }
            bytes
        }
    };
    let columns = original.columns.as_ref().map(|map| {
        if rng.random_bool(0.1) {
            let mut bytes = map.clone().into_bytes();
            mutate(&mut bytes, reader, &mut rng);
            String::from_utf8_lossy(&bytes).into_owned()
        } else {
            map.clone()
        }
    });
    Case { seed, bytes, columns }
}

/// 1 to 6 mutations, fewer more often: most cases differ from a valid file in one place.
fn mutation_count(rng: &mut ChaCha8Rng) -> usize {
    [1, 1, 1, 1, 2, 2, 2, 3, 4, 6][rng.random_range(0..10)]
}

/// Tokens of the seed, shuffled and joined: text with the format's words and punctuation.
fn token_soup(bytes: &[u8], reader: Reader, rng: &mut ChaCha8Rng) -> Vec<u8> {
    let spans = tokens(bytes);
    let mut out = Vec::new();
    for _ in 0..rng.random_range(1..600) {
        match rng.random_range(0..8) {
            0 => out.extend_from_slice(words(reader).choose(rng).unwrap_or(&"").as_bytes()),
            1 => out.extend_from_slice(NUMBERS.choose(rng).unwrap_or(&"").as_bytes()),
            _ => {
                if let Some(&(a, b)) = spans.choose(rng) {
                    out.extend_from_slice(&bytes[a..b]);
                }
            }
        }
    }
    out
}

/// Byte spans of the tokens: runs of `[A-Za-z0-9_.+-]` (words and numbers), and every other byte
/// on its own (separators, brackets, quotes, line ends).
fn tokens(bytes: &[u8]) -> Vec<(usize, usize)> {
    let word = |b: u8| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'.' | b'+' | b'-');
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        if word(bytes[i]) {
            while i < bytes.len() && word(bytes[i]) {
                i += 1;
            }
        } else {
            i += 1;
        }
        spans.push((start, i));
    }
    spans
}

/// Byte spans of the lines, each with its line end.
fn lines(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'\n' {
            spans.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < bytes.len() {
        spans.push((start, bytes.len()));
    }
    spans
}

/// A count from 1 to `most`, log-uniform: small counts as often as huge ones.
fn log_count(rng: &mut ChaCha8Rng, most: usize) -> usize {
    let exponent = rng.random_range(0.0..(most as f64).ln());
    (exponent.exp() as usize).clamp(1, most)
}

fn replace(bytes: &mut Vec<u8>, (a, b): (usize, usize), with: &[u8]) {
    bytes.splice(a..b, with.iter().copied());
}

/// Swaps two spans (`first` before `second`, not overlapping).
fn swap(bytes: &mut Vec<u8>, first: (usize, usize), second: (usize, usize)) {
    let (a, b) = (bytes[first.0..first.1].to_vec(), bytes[second.0..second.1].to_vec());
    replace(bytes, second, &a);
    replace(bytes, first, &b);
}

/// One mutation of `bytes`.
fn mutate(bytes: &mut Vec<u8>, reader: Reader, rng: &mut ChaCha8Rng) {
    match rng.random_range(0..18) {
        kind @ 0..=5 => mutate_tokens(bytes, reader, rng, kind),
        kind @ 6..=8 => mutate_lines(bytes, rng, kind),
        kind @ 9..=11 => mutate_bytes(bytes, rng, kind),
        kind => mutate_at_scale(bytes, rng, kind),
    }
}

/// A position in `bytes` (its end included), drawn from `rng`.
fn at(bytes: &[u8], rng: &mut ChaCha8Rng) -> usize {
    if bytes.is_empty() { 0 } else { rng.random_range(0..=bytes.len()) }
}

/// Mutations 0–5: of one token or two.
fn mutate_tokens(bytes: &mut Vec<u8>, reader: Reader, rng: &mut ChaCha8Rng, kind: i32) {
    let spans = tokens(bytes);
    let token = |rng: &mut ChaCha8Rng| spans.choose(rng).copied().unwrap_or((0, 0));
    let words_only: Vec<(usize, usize)> =
        spans.iter().copied().filter(|&(a, b)| b > a + 1 || bytes[a].is_ascii_alphanumeric()).collect();
    let word = |rng: &mut ChaCha8Rng| words_only.choose(rng).copied().unwrap_or((0, 0));
    match kind {
        // A cell (token) deleted, duplicated, or swapped with another.
        0 => replace(bytes, token(rng), b""),
        1 => {
            let span = token(rng);
            let copy = bytes[span.0..span.1].to_vec();
            bytes.splice(span.1..span.1, copy);
        }
        2 => {
            let (x, y) = (word(rng), word(rng));
            if x.1 <= y.0 {
                swap(bytes, x, y);
            } else if y.1 <= x.0 {
                swap(bytes, y, x);
            }
        }
        // A number or a name replaced by one the format must handle or refuse.
        3 | 4 => replace(bytes, word(rng), NUMBERS.choose(rng).unwrap_or(&"").as_bytes()),
        _ => replace(bytes, word(rng), words(reader).choose(rng).unwrap_or(&"").as_bytes()),
    }
}

/// Mutations 6–8: of whole lines.
fn mutate_lines(bytes: &mut Vec<u8>, rng: &mut ChaCha8Rng, kind: i32) {
    match kind {
        // Lines deleted, duplicated (up to thousands of times), swapped.
        6 => {
            if let Some(&line) = lines(bytes).choose(rng) {
                replace(bytes, line, b"");
            }
        }
        7 => {
            if let Some(&(a, b)) = lines(bytes).choose(rng) {
                let copies = log_count(rng, 5000).min(MAX_LEN / (b - a).max(1));
                let line = bytes[a..b].repeat(copies);
                bytes.splice(b..b, line);
            }
        }
        _ => {
            let all = lines(bytes);
            if all.len() >= 2 {
                let i = rng.random_range(0..all.len() - 1);
                let j = rng.random_range(i + 1..all.len());
                swap(bytes, all[i], all[j]);
            }
        }
    }
}

/// Mutations 9–11: of bytes, regardless of the format.
fn mutate_bytes(bytes: &mut Vec<u8>, rng: &mut ChaCha8Rng, kind: i32) {
    match kind {
        // Truncated anywhere, even inside a UTF-8 sequence.
        9 => {
            let end = at(bytes, rng);
            bytes.truncate(end);
        }
        10 => {
            let position = at(bytes, rng);
            bytes.splice(position..position, INVALID_UTF8.choose(rng).unwrap_or(&&b"\xff"[..]).iter().copied());
        }
        _ => {
            if !bytes.is_empty() {
                let i = rng.random_range(0..bytes.len());
                bytes[i] ^= 1 << rng.random_range(0..8);
            }
        }
    }
}

/// Mutations 12–17: long lines, deep nesting, many distinct names, separators, noise.
fn mutate_at_scale(bytes: &mut Vec<u8>, rng: &mut ChaCha8Rng, kind: i32) {
    match kind {
        // A long line: a token repeated up to 200,000 times (100,000-column headers).
        12 => {
            let span = tokens(bytes).choose(rng).copied().unwrap_or((0, 0));
            let copies = log_count(rng, 200_000).min(MAX_LEN / (span.1 - span.0).max(1));
            let run = bytes[span.0..span.1].repeat(copies);
            bytes.splice(span.1..span.1, run);
        }
        // Deep nesting.
        13 => {
            let position = at(bytes, rng);
            let run = OPENERS.choose(rng).unwrap_or(&"(").repeat(log_count(rng, 100_000));
            bytes.splice(position..position, run.into_bytes());
        }
        // The other separator or decimal mark, everywhere.
        14 => {
            let (from, to) = [(b',', b';'), (b';', b','), (b'.', b','), (b',', b'.')][rng.random_range(0..4)];
            bytes.iter_mut().filter(|b| **b == from).for_each(|b| *b = to);
        }
        // Many distinct cells, names or elements: what makes a lookup by scanning quadratic.
        15 => {
            let position = at(bytes, rng);
            let count = log_count(rng, 100_000);
            let (prefix, suffix) = [(",c", ""), (";c", ""), ("<link name=\"l", "\"/>"), (" a", "=\"\""), ("\nr", ",t")]
                [rng.random_range(0..5)];
            let run = distinct(prefix, suffix, count);
            bytes.splice(position..position, run.into_bytes().into_iter().take(MAX_LEN));
        }
        // Deep nesting that closes again: a recursive walk of the tree.
        16 => {
            let position = at(bytes, rng);
            let depth = log_count(rng, 100_000);
            let (open, close) = [("(", ")"), ("[", "]"), ("<a>", "</a>"), ("Some(", ")")][rng.random_range(0..4)];
            let run = open.repeat(depth) + &close.repeat(depth);
            bytes.splice(position..position, run.into_bytes());
        }
        _ => {
            let position = at(bytes, rng);
            let noise: Vec<u8> = (0..rng.random_range(1..16)).map(|_| rng.random()).collect();
            bytes.splice(position..position, noise);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seeds() -> Vec<Seed> {
        let seed = |text: &str| Seed {
            name: "s".into(),
            extension: "csv",
            bytes: text.as_bytes().to_vec(),
            joints: None,
            columns: Some("x_mm=X".into()),
        };
        vec![seed("q1_rad,X,y_mm,z_mm\n0.1,1,2,3\n"), seed("(a: 1.5, b: [1, 2])")]
    }

    #[test]
    fn a_case_is_a_function_of_the_seed_the_reader_and_its_number_alone() {
        let seeds = seeds();
        let first: Vec<Case> = (0..200).map(|i| generate(&seeds, &[], Reader::Csv, 7, i)).collect();
        let again: Vec<Case> = (0..200).rev().map(|i| generate(&seeds, &[], Reader::Csv, 7, i)).collect();
        assert!(first.iter().eq(again.iter().rev()));
        let other: Vec<Case> = (0..200).map(|i| generate(&seeds, &[], Reader::Robot, 7, i)).collect();
        assert_ne!(first, other);
        assert!(first.iter().filter(|c| c.bytes != seeds[c.seed].bytes).count() > 150);
        assert!(first.iter().all(|c| c.bytes.len() <= MAX_LEN));
    }

    #[test]
    fn tokens_and_lines_cover_the_bytes() {
        let bytes = b"q1_rad,x_mm\n-1.5e3,\"a b\"\n";
        let spans = tokens(bytes);
        assert_eq!(spans.iter().map(|(a, b)| b - a).sum::<usize>(), bytes.len());
        assert_eq!(&bytes[spans[0].0..spans[0].1], b"q1_rad");
        assert_eq!(&bytes[spans[3].0..spans[3].1], b"\n");
        assert_eq!(lines(bytes), [(0, 12), (12, bytes.len())]);
    }

    #[test]
    fn the_regressions_come_first_then_random_cases() {
        let seeds = seeds();
        let regressions = regressions(&seeds, Reader::Csv);
        assert_eq!(generate(&seeds, &regressions, Reader::Csv, 7, 0), regressions[0]);
        assert!(regressions.iter().all(|c| c.bytes.len() <= MAX_LEN));
        let after = regressions.len() as u64;
        assert_eq!(generate(&seeds, &regressions, Reader::Csv, 7, after), generate(&seeds, &[], Reader::Csv, 7, after));
    }
}
