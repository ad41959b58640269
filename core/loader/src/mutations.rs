//! Mutated scene files through the whole loader (the formats' mutation tests): each case
//! changes a scene a few times (a byte changed, inserted or removed; a number replaced by an
//! extreme one; a line dropped, repeated or swapped with another) and loads it, strictly or
//! leniently: an error or a scene, never a panic.

use std::path::Path;

/// A xorshift generator: the same cases on every run.
pub struct Cases(u64);

impl Cases {
    pub fn new(seed: u64) -> Cases {
        Cases(seed)
    }

    /// A number in [0, m) (0 when m is 0).
    pub fn below(&mut self, m: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % m.max(1) as u64) as usize
    }
}

const NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1e30",
    "-1e30",
    "nan",
    "inf",
    "3.5",
    "100000",
    "2147483648",
    "-0",
];

/// `text` changed one to three times; `bytes` are the characters a changed or inserted byte
/// takes (the format's punctuation).
pub fn mutate(text: &str, bytes: &[u8], cases: &mut Cases) -> String {
    let mut text = text.to_string();
    for _ in 0..1 + cases.below(3) {
        match cases.below(4) {
            0 => {
                let mut b = text.into_bytes();
                let at = cases.below(b.len());
                match cases.below(3) {
                    0 => b[at] = bytes[cases.below(bytes.len())],
                    1 => b.insert(at, bytes[cases.below(bytes.len())]),
                    _ => {
                        b.remove(at);
                    }
                }
                text = String::from_utf8_lossy(&b).into_owned();
            }
            1 => {
                let b = text.as_bytes();
                let mut spans = Vec::new();
                let mut i = 0;
                while i < b.len() {
                    if b[i].is_ascii_digit() {
                        let start = i;
                        while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                            i += 1;
                        }
                        spans.push((start, i));
                    }
                    i += 1;
                }
                if let Some(&(s, e)) = spans.get(cases.below(spans.len())) {
                    text.replace_range(s..e, NUMBERS[cases.below(NUMBERS.len())]);
                }
            }
            2 => {
                let mut lines: Vec<&str> = text.lines().collect();
                let at = cases.below(lines.len());
                if cases.below(2) == 0 {
                    lines.remove(at);
                } else {
                    let l = lines[at];
                    lines.insert(cases.below(lines.len()), l);
                }
                text = lines.join("\n");
            }
            _ => {
                let mut lines: Vec<&str> = text.lines().collect();
                let (a, b) = (cases.below(lines.len()), cases.below(lines.len()));
                lines.swap(a, b);
                text = lines.join("\n");
            }
        }
    }
    text
}

/// Loads `n` mutations of the scene `base` written at `path` (whose folder holds what it
/// names): panics with the scene text if the loader panics, and checks that both outcomes
/// happen (a tenth of the cases at least).
pub fn check(path: &Path, base: &str, bytes: &[u8], n: usize, seed: u64) {
    std::fs::write(path, base).unwrap();
    crate::load::load_with(path, &[], &[], false).unwrap_or_else(|e| panic!("the base scene: {e}"));
    let mut cases = Cases::new(seed);
    let mut outcomes = [0usize; 2];
    for _ in 0..n {
        let text = mutate(base, bytes, &mut cases);
        std::fs::write(path, &text).unwrap();
        let lenient = cases.below(2) == 0;
        match std::panic::catch_unwind(|| crate::load::load_with(path, &[], &[], lenient)) {
            Ok(r) => outcomes[r.is_ok() as usize] += 1,
            Err(_) => panic!("the loader panicked on:\n{text}"),
        }
    }
    assert!(
        outcomes[0] > n / 10 && outcomes[1] > n / 10,
        "errors, scenes: {outcomes:?}"
    );
}

/// The number of cases: the environment variable `var` when set, else `default`.
pub fn count(var: &str, default: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}
