//! Seeded mutation test of the whole IGES reader (parse, then conversion to NURBS): every
//! mutant of the bundled fixtures must give a geometry or an error — never a panic, a stack
//! overflow (which would abort the test process) or a hang.
//!
//! Most mutations edit a fixture taken apart into its entities and write it back as a
//! well-formed file (sequence numbers, parameter pointers and line counts, Terminate
//! counts all right), so that they get past the record checks and reach the parameter
//! reader, the reference checks and the conversion: pointers redirected to the entity
//! itself, to a parent (cycles) or elsewhere, transformation pointers (DE field 7) chained
//! into cycles, counts and degrees made huge, entity types and subordinate switches
//! changed, entities duplicated or removed, tokens corrupted. A few mutations then damage
//! the text itself (characters, duplicated or dropped lines, truncation).
//!
//! Each mutant is a pure function of (fixture, index), so a failure names what to replay.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use super::tests::fixture;
use super::*;
use crate::iges::geometry_from_iges;
use crate::EntityGeometry;

/// The fixtures mutated, and how many mutants of each (the wing body is larger: fewer).
const CORPUS: [(&str, usize); 5] = [
    ("formats/torus.igs", 2400),
    ("formats/cylinder.igs", 2400),
    ("sphere/sphere.igs", 2400),
    ("naca0012/naca0012.igs", 2400),
    ("cad/wing_body.igs", 600),
];

/// Multiplies the mutant counts (environment variable `IGES_FUZZ_SCALE`, default 1) and
/// changes the seed (`IGES_FUZZ_SEED`): longer local runs search further; CI runs the
/// default, fixed set.
fn knob(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A mutant running longer than this is taken for a hang (conversions of the fixtures take
/// milliseconds).
const MUTANT_TIME_LIMIT: Duration = Duration::from_secs(30);

/// Stack of the thread that runs the mutants: the default of spawned threads, named so a
/// change of that default cannot hide a deep recursion.
const MUTANT_STACK: usize = 2 << 20;

/// splitmix64: a small, fixed, portable generator for reproducible mutants.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (0 when `n` is 0).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> Option<&'a T> {
        (!items.is_empty()).then(|| &items[self.below(items.len())])
    }
}

// ---------------------------------------------------------------------------------------------
// a fixture taken apart
// ---------------------------------------------------------------------------------------------

/// One entity: its two Directory Entry records (columns 1–72) and its parameters (the
/// entity type first; the record delimiter dropped).
#[derive(Clone)]
struct Entity {
    d1: String,
    d2: String,
    tokens: Vec<String>,
}

impl Entity {
    /// Directory field `k` (1–9) of the first record, or 11–19 of the second, trimmed.
    fn field(&self, k: usize) -> &str {
        let (record, k) = if k <= 9 {
            (&self.d1, k)
        } else {
            (&self.d2, k - 10)
        };
        record[8 * k - 8..8 * k].trim()
    }

    fn set_field(&mut self, k: usize, value: &str) {
        let (record, k) = if k <= 9 {
            (&mut self.d1, k)
        } else {
            (&mut self.d2, k - 10)
        };
        record.replace_range(8 * k - 8..8 * k, &format!("{value:>8.8}"));
    }

    fn type_number(&self) -> i32 {
        self.field(1).parse().unwrap_or(0)
    }

    /// Changes the type in both Directory records and in the parameters.
    fn set_type(&mut self, t: i32) {
        self.set_field(1, &t.to_string());
        self.set_field(11, &t.to_string());
        if let Some(first) = self.tokens.first_mut() {
            *first = t.to_string();
        }
    }
}

/// The Start and Global records kept as written, and the entities.
#[derive(Clone)]
struct Skeleton {
    head: Vec<String>,
    entities: Vec<Entity>,
}

impl Skeleton {
    /// Takes a well-formed fixed-format file apart (the fixtures have no Hollerith strings
    /// in their parameter data, so `,` and `;` always delimit).
    fn parse(text: &str) -> Skeleton {
        let lines: Vec<&str> = text.lines().collect();
        let of = |letter: u8| lines.iter().filter(move |l| l.as_bytes()[72] == letter);
        let head = lines
            .iter()
            .filter(|l| matches!(l.as_bytes()[72], b'S' | b'G'))
            .map(|l| l.to_string())
            .collect();
        let d: Vec<&str> = of(b'D').copied().collect();
        let mut entities: Vec<Entity> = d
            .chunks(2)
            .map(|pair| Entity {
                d1: pair[0][..72].to_string(),
                d2: pair[1][..72].to_string(),
                tokens: Vec::new(),
            })
            .collect();
        let mut data = vec![String::new(); entities.len()];
        for l in of(b'P') {
            let de: usize = l[65..72].trim().parse().expect("a back pointer");
            data[(de - 1) / 2] += &l[..64];
        }
        for (e, data) in entities.iter_mut().zip(data) {
            let data = data.trim_end().trim_end_matches(';');
            e.tokens = data.split(',').map(|t| t.trim().to_string()).collect();
        }
        Skeleton { head, entities }
    }

    /// Writes the file back: parameter data in 64-column records, Directory fields 2 and
    /// 14 (parameter pointer and line count), sequence numbers and the Terminate counts
    /// made consistent.
    fn text(&self) -> String {
        let record = |data: &str, letter: char, seq: usize| format!("{data:<72}{letter}{seq:07}");
        let mut lines: Vec<String> = self.head.clone();
        let (mut d, mut p) = (Vec::new(), Vec::new());
        for (i, e) in self.entities.iter().enumerate() {
            let de = 2 * i + 1;
            let data = self.entities[i].tokens.join(",") + ";";
            let chunks: Vec<&[u8]> = data.as_bytes().chunks(64).collect();
            let mut e = e.clone();
            e.set_field(2, &(p.len() + 1).to_string());
            e.set_field(14, &chunks.len().to_string());
            d.push(record(&e.d1, 'D', de));
            d.push(record(&e.d2, 'D', de + 1));
            for c in chunks {
                let text = format!("{:<64} {de:>7}", String::from_utf8_lossy(c));
                p.push(record(&text, 'P', p.len() + 1));
            }
        }
        let count = |letter: u8| {
            self.head
                .iter()
                .filter(|l| l.as_bytes()[72] == letter)
                .count()
        };
        let terminate = format!(
            "S{:>7}G{:>7}D{:>7}P{:>7}",
            count(b'S'),
            count(b'G'),
            d.len(),
            p.len()
        );
        lines.extend(d);
        lines.extend(p);
        lines.push(record(&terminate, 'T', 1));
        lines.join("\n") + "\n"
    }

    /// DE numbers of all entities, and of the 124 matrices.
    fn des(&self) -> Vec<usize> {
        (0..self.entities.len()).map(|i| 2 * i + 1).collect()
    }

    fn matrix_des(&self) -> Vec<usize> {
        (0..self.entities.len())
            .filter(|&i| self.entities[i].type_number() == 124)
            .map(|i| 2 * i + 1)
            .collect()
    }

    /// (entity, token) positions holding a pointer to `de`-like values: odd integers naming
    /// an existing entity (knots and counts may look alike: that is fine for mutations).
    fn pointer_tokens(&self) -> Vec<(usize, usize)> {
        let n = self.entities.len();
        let mut out = Vec::new();
        for (i, e) in self.entities.iter().enumerate() {
            for (k, t) in e.tokens.iter().enumerate().skip(1) {
                if let Ok(v) = t.parse::<usize>() {
                    if v % 2 == 1 && v < 2 * n {
                        out.push((i, k));
                    }
                }
            }
        }
        out
    }
}

// ---------------------------------------------------------------------------------------------
// mutations
// ---------------------------------------------------------------------------------------------

/// Values that break counts, degrees and pointers.
const NASTY: [&str; 14] = [
    "0",
    "-1",
    "-7",
    "1",
    "2",
    "3",
    "24",
    "25",
    "64",
    "4000000000",
    "999999999999999",
    "1.E300",
    "-1.E300",
    "",
];

/// Parameter index of counts and degrees by entity type (after the type number).
fn size_fields(entity_type: i32) -> &'static [usize] {
    match entity_type {
        102 => &[1],
        126 => &[1, 2],
        128 => &[1, 2, 3, 4],
        144 => &[2, 3],
        _ => &[],
    }
}

/// One structural mutation of the skeleton.
fn mutate(s: &mut Skeleton, rng: &mut Rng) {
    let n = s.entities.len();
    if n == 0 {
        return;
    }
    let des = s.des();
    let i = rng.below(n);
    let own = 2 * i + 1;
    match rng.below(14) {
        // a pointer redirected: to itself, to a parent (a cycle of two), anywhere
        0 | 1 => {
            let Some(&(a, k)) = rng.pick(&s.pointer_tokens()) else {
                return;
            };
            let a_de = (2 * a + 1).to_string();
            let parents: Vec<usize> = (0..n)
                .filter(|&p| s.entities[p].tokens.iter().skip(1).any(|t| *t == a_de))
                .map(|p| 2 * p + 1)
                .collect();
            let target = match rng.below(3) {
                0 => 2 * a + 1,
                1 => rng.pick(&parents).copied().unwrap_or(2 * a + 1),
                _ => *rng.pick(&des).unwrap_or(&1),
            };
            s.entities[a].tokens[k] = target.to_string();
        }
        // any parameter replaced
        2 => {
            let e = &mut s.entities[i];
            let k = 1 + rng.below(e.tokens.len().saturating_sub(1));
            let value = match rng.below(3) {
                0 => own.to_string(),
                1 => des[rng.below(n)].to_string(),
                _ => NASTY[rng.below(NASTY.len())].to_string(),
            };
            if k < e.tokens.len() {
                e.tokens[k] = value;
            }
        }
        // a count or degree changed
        3 => {
            let e = &mut s.entities[i];
            if let Some(&k) = rng.pick(size_fields(e.type_number())) {
                if k < e.tokens.len() {
                    e.tokens[k] = NASTY[rng.below(NASTY.len())].to_string();
                }
            }
        }
        // DE field 7: a matrix (possibly forming a chain or cycle), itself, anything, none
        4 | 5 => {
            let matrices = s.matrix_des();
            let target = match rng.below(4) {
                0 => own,
                1 => *rng.pick(&des).unwrap_or(&0),
                2 => 0,
                _ => *rng.pick(&matrices).unwrap_or(&own),
            };
            let k = if rng.below(2) == 0 && !matrices.is_empty() {
                (matrices[rng.below(matrices.len())] - 1) / 2
            } else {
                i
            };
            s.entities[k].set_field(7, &target.to_string());
        }
        // subordinate switch or form number
        6 => {
            let e = &mut s.entities[i];
            if rng.below(2) == 0 {
                let status = format!("000{}0000", rng.below(4));
                e.d1.replace_range(64..72, &status[..8]);
            } else {
                e.set_field(15, &rng.below(13).to_string());
            }
        }
        // another entity type
        7 => {
            const TYPES: [i32; 15] = [
                0, 100, 102, 104, 108, 110, 120, 122, 124, 126, 128, 142, 144, 402, 186,
            ];
            s.entities[i].set_type(TYPES[rng.below(TYPES.len())]);
        }
        // an entity appended again, and something pointed at the copy
        8 => {
            let copy = s.entities[i].clone();
            s.entities.push(copy);
            let copy_de = 2 * n + 1;
            if let Some(&(a, k)) = rng.pick(&s.pointer_tokens()) {
                s.entities[a].tokens[k] = copy_de.to_string();
            }
        }
        // an entity removed (later DE numbers shift under their pointers)
        9 => {
            s.entities.remove(i);
        }
        // a parameter removed, repeated or swapped
        10 => {
            let e = &mut s.entities[i];
            let len = e.tokens.len();
            if len < 2 {
                return;
            }
            let (a, b) = (1 + rng.below(len - 1), 1 + rng.below(len - 1));
            match rng.below(3) {
                0 => {
                    e.tokens.remove(a);
                }
                1 => {
                    let t = e.tokens[a].clone();
                    e.tokens.insert(a, t);
                }
                _ => e.tokens.swap(a, b),
            }
        }
        // a real number made extreme, zero, negative or equal to a neighbour (degenerate
        // radii, knots out of order, zero weights, singular matrices, overflow)
        11 | 12 => {
            let e = &mut s.entities[i];
            let reals: Vec<usize> = (1..e.tokens.len())
                .filter(|&k| e.tokens[k].contains('.'))
                .collect();
            let Some(&k) = rng.pick(&reals) else {
                return;
            };
            let x: f64 = e.tokens[k].replace(['D', 'd'], "E").parse().unwrap_or(1.0);
            let neighbour = e.tokens[if k > 1 { k - 1 } else { k }].clone();
            e.tokens[k] = match rng.below(7) {
                0 => "0.".to_string(),
                1 => format!("{:E}", -x),
                2 => format!("{:E}", x * 1e200),
                3 => format!("{:E}", x * 1e-200),
                4 => format!("{:E}", x + 1e-9),
                5 => "1.7E308".to_string(),
                _ => neighbour,
            };
        }
        // a character of a parameter replaced
        _ => {
            let e = &mut s.entities[i];
            let k = rng.below(e.tokens.len());
            let mut b = e.tokens[k].clone().into_bytes();
            let c = b"0123456789-+.EDH X,;"[rng.below(20)];
            if b.is_empty() {
                b.push(c);
            } else {
                let at = rng.below(b.len());
                b[at] = c;
            }
            e.tokens[k] = String::from_utf8_lossy(&b).into_owned();
        }
    }
}

/// One mutation of the text itself.
fn damage(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        return String::new();
    }
    let i = rng.below(lines.len());
    match rng.below(4) {
        0 => {
            let mut b = lines[i].clone().into_bytes();
            if !b.is_empty() {
                let at = rng.below(b.len());
                b[at] = b"0123456789,;-.EDH X"[rng.below(19)];
            }
            lines[i] = String::from_utf8_lossy(&b).into_owned();
        }
        1 => {
            let copy = lines[i].clone();
            lines.insert(i, copy);
        }
        2 => {
            lines.remove(i);
        }
        _ => lines.truncate(i),
    }
    lines.join("\n") + "\n"
}

/// Mutant `index` of a fixture: one to four structural mutations, then in one case of
/// eight a damage to the text.
fn mutant(skeleton: &Skeleton, seed: u64, fixture: usize, index: usize) -> String {
    // the seed hashed first: seeds differing in low bits must not give the same mutants
    // in another order
    let mut rng = Rng(Rng(seed).next() ^ ((fixture as u64) << 32) ^ index as u64);
    let mut s = skeleton.clone();
    for _ in 0..1 + rng.below(4) {
        mutate(&mut s, &mut rng);
    }
    let text = s.text();
    if rng.below(8) == 0 {
        damage(&text, &mut rng)
    } else {
        text
    }
}

// ---------------------------------------------------------------------------------------------
// the test
// ---------------------------------------------------------------------------------------------

/// What one mutant gave.
enum Outcome {
    Converted,
    /// Rejected by the parser, with the error's kind.
    ParseError(&'static str),
    /// Parsed, rejected by the conversion.
    ConversionError(&'static str),
    /// A panic (its message) or an invalid result.
    Failure(String),
}

fn run(text: &str) -> Outcome {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let model = parse_iges(text).map_err(|e| (true, e))?;
        geometry_from_iges(&model).map_err(|e| (false, e))
    }));
    match result {
        Err(panic) => Outcome::Failure(format!(
            "panicked: {}",
            panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("?")
        )),
        Ok(Err((_, e))) if e.line().is_none() => Outcome::Failure(format!("no line: {e}")),
        Ok(Err((true, e))) => Outcome::ParseError(kind(&e)),
        Ok(Err((false, e))) => Outcome::ConversionError(kind(&e)),
        Ok(Ok(model)) => check_geometry(&model),
    }
}

/// The error's variant, for the tally.
fn kind(e: &IgesError) -> &'static str {
    match e {
        IgesError::Io { .. } => "Io",
        IgesError::Syntax { .. } => "Syntax",
        IgesError::Section { .. } => "Section",
        IgesError::Sequence { .. } => "Sequence",
        IgesError::BackPointer { .. } => "BackPointer",
        IgesError::Parameter { .. } => "Parameter",
        IgesError::Unsupported { .. } => "Unsupported",
        IgesError::Geometry { .. } => "Geometry",
        IgesError::UnboundedPlane { .. } => "UnboundedPlane",
        IgesError::ReferenceCycle { .. } => "ReferenceCycle",
        IgesError::NestingTooDeep { .. } => "NestingTooDeep",
        IgesError::ExpansionTooLarge { .. } => "ExpansionTooLarge",
        IgesError::Units { .. } => "Units",
    }
}

/// A converted model must hold valid NURBS (finite, consistent): callers rely on it.
fn check_geometry(model: &crate::GeometryModel) -> Outcome {
    for e in &model.entities {
        let valid = match &e.geometry {
            EntityGeometry::Curve(c) => c.validate(),
            EntityGeometry::Surface(s) => s.validate(),
        };
        if let Err(err) = valid {
            return Outcome::Failure(format!(
                "entity {} ({}) is invalid: {err}",
                e.name, e.origin
            ));
        }
    }
    Outcome::Converted
}

#[test]
fn mutated_files_give_a_geometry_or_an_error_never_a_panic_or_a_hang() {
    let started = Instant::now();
    let scale = knob("IGES_FUZZ_SCALE", 1) as usize;
    let seed = knob("IGES_FUZZ_SEED", 0x5EED_1663);
    let (sender, receiver) = mpsc::channel();
    // The mutants run on a worker so that this thread can notice one that never ends.
    let worker = std::thread::Builder::new()
        .name("iges-mutants".into())
        .stack_size(MUTANT_STACK)
        .spawn(move || {
            for (f, &(rel, count)) in CORPUS.iter().enumerate() {
                let skeleton = Skeleton::parse(&fixture(rel));
                for k in 0..count * scale {
                    let outcome = run(&mutant(&skeleton, seed, f, k));
                    if sender.send((f, k, outcome)).is_err() {
                        return;
                    }
                }
            }
        })
        .expect("a worker thread");
    let total: usize = CORPUS.iter().map(|c| c.1 * scale).sum();
    let (mut converted, mut parse_errors, mut conversion_errors) = (0, 0, 0);
    let mut tally: std::collections::BTreeMap<String, usize> = Default::default();
    let mut failures = Vec::new();
    // (fixture, index) of the last mutant done: the next one is the one that hangs
    let mut last = None;
    for _ in 0..total {
        let (f, k, outcome) = match receiver.recv_timeout(MUTANT_TIME_LIMIT) {
            Ok(x) => x,
            Err(_) => panic!(
                "the mutant after {last:?} (seed {seed:#x}) ran over {MUTANT_TIME_LIMIT:?}: \
                 replay with mutant(&Skeleton::parse(&fixture(..)), seed, f, k)"
            ),
        };
        last = Some((CORPUS[f].0, k));
        match outcome {
            Outcome::Converted => converted += 1,
            Outcome::ParseError(k) => {
                parse_errors += 1;
                *tally.entry(format!("parse: {k}")).or_default() += 1;
            }
            Outcome::ConversionError(k) => {
                conversion_errors += 1;
                *tally.entry(format!("conversion: {k}")).or_default() += 1;
            }
            Outcome::Failure(why) => failures.push(format!(
                "{} mutant {k} (seed {seed:#x}): {why}",
                CORPUS[f].0
            )),
        }
    }
    worker.join().expect("the worker ends");
    let elapsed = started.elapsed();
    eprintln!(
        "{total} mutants in {:.1} s: {converted} converted, {conversion_errors} conversion \
         errors, {parse_errors} parse errors, {} failures",
        elapsed.as_secs_f64(),
        failures.len()
    );
    eprintln!("errors: {tally:?}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The mutants must reach every stage: a mutator whose files all fail to parse would
    // test nothing of the references or the conversion.
    assert!(converted > total / 10, "{converted} of {total} converted");
    assert!(
        conversion_errors > total / 10,
        "{conversion_errors} of {total}"
    );
    assert!(parse_errors > total / 10, "{parse_errors} of {total}");
}

#[test]
fn skeletons_write_back_the_fixtures_they_were_taken_from() {
    // The mutator's writer must itself produce valid files, or every mutant would be a
    // mere syntax error.
    for (rel, _) in CORPUS {
        let text = fixture(rel);
        let original = parse_iges(&text).expect("the fixture parses");
        // unmutated, every fixture converts: mutants start from a file that reaches the end
        geometry_from_iges(&original).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let rewritten = parse_iges(&Skeleton::parse(&text).text()).expect("rewritten parses");
        assert_eq!(rewritten.entities.len(), original.entities.len(), "{rel}");
        for (a, b) in rewritten.entities.iter().zip(&original.entities) {
            assert_eq!(a.kind, b.kind, "{rel} DE {}", a.de);
            assert_eq!(a.transform, b.transform, "{rel} DE {}", a.de);
        }
    }
}
