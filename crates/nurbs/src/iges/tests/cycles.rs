//! References that lead back to themselves or nest absurdly deep, and a seeded mutation
//! test of the whole reader (parse, then conversion to NURBS): every mutant must give a
//! geometry or an error, never a panic, a stack overflow or a hang.

use super::tests::{build, ent, fixture, GLOBAL};
use super::*;
use crate::iges::geometry_from_iges;

fn convert(text: &str) -> Result<crate::GeometryModel, IgesError> {
    geometry_from_iges(&parse_iges(text)?)
}

#[test]
fn a_composite_curve_that_contains_itself_is_a_clear_error() {
    let text = build(GLOBAL, &[ent(102, "102,1,1;")]);
    match convert(&text) {
        Err(IgesError::ReferenceCycle {
            de: 1,
            entity_type: 102,
            cycle,
            ..
        }) => assert_eq!(cycle, "1 -> 1"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_trimmed_surface_whose_surface_is_itself_is_a_clear_error() {
    let text = build(GLOBAL, &[ent(144, "144,1,0,0,0;")]);
    let err = convert(&text).expect_err("a cycle");
    assert!(
        matches!(err, IgesError::ReferenceCycle { de: 1, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("refers to itself"), "{err}");
}

#[test]
fn a_cycle_through_several_entities_names_them() {
    // 102 (DE 1) holds 102 (DE 3), which holds a line and DE 1 again.
    let text = build(
        GLOBAL,
        &[
            ent(102, "102,1,3;"),
            ent(102, "102,2,5,1;"),
            ent(110, "110,0.,0.,0.,1.,0.,0.;"),
        ],
    );
    match convert(&text) {
        Err(IgesError::ReferenceCycle { cycle, .. }) => assert_eq!(cycle, "1 -> 3 -> 1"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn nesting_deeper_than_the_limit_is_a_clear_error_and_within_it_converts() {
    let chain = |depth: usize| {
        // Composite k holds composite k + 1; the last holds a line.
        let params: Vec<String> = (0..depth)
            .map(|k| format!("102,1,{};", 2 * (k + 1) + 1))
            .chain(std::iter::once("110,0.,0.,0.,1.,0.,0.;".to_string()))
            .collect();
        let ents: Vec<_> = params
            .iter()
            .enumerate()
            .map(|(k, p)| ent(if k < depth { 102 } else { 110 }, p))
            .collect();
        build(GLOBAL, &ents)
    };
    let err = convert(&chain(MAX_NESTING + 5)).expect_err("too deep");
    assert!(matches!(err, IgesError::NestingTooDeep { .. }), "{err}");
    let model = convert(&chain(MAX_NESTING - 2)).expect("a chain within the limit converts");
    assert_eq!(model.entities.len(), 1);
}

/// splitmix64: a small, fixed, portable generator for reproducible mutants.
struct Mutator(u64);

impl Mutator {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    /// One mutation of an IGES text: an integer of the parameter data replaced (by a DE
    /// number, possibly the entity's own, or by a huge or negative count), a character
    /// replaced, a line duplicated or dropped, or the file truncated.
    fn mutate(&mut self, text: &str) -> String {
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        let parameter_lines: Vec<usize> = (0..lines.len())
            .filter(|&i| lines[i].as_bytes().get(72) == Some(&b'P'))
            .collect();
        let directory_entries = lines
            .iter()
            .filter(|l| l.as_bytes().get(72) == Some(&b'D'))
            .count();
        match self.below(6) {
            0 | 1 if !parameter_lines.is_empty() => {
                let i = parameter_lines[self.below(parameter_lines.len())];
                let data: String = lines[i].chars().take(64).collect();
                let tokens: Vec<&str> = data.split([',', ';']).collect();
                let k = self.below(tokens.len());
                let replacement = match self.below(4) {
                    0 => (2 * self.below(directory_entries / 2 + 1) + 1).to_string(),
                    1 => "999999999".to_string(),
                    2 => "-7".to_string(),
                    _ => self.below(40).to_string(),
                };
                let mut new_tokens: Vec<String> = tokens.iter().map(|t| t.to_string()).collect();
                new_tokens[k] = replacement;
                let mut joined = String::new();
                let separators: Vec<char> =
                    data.chars().filter(|c| *c == ',' || *c == ';').collect();
                for (j, t) in new_tokens.iter().enumerate() {
                    joined += t;
                    if let Some(sep) = separators.get(j) {
                        joined.push(*sep);
                    }
                }
                let rest: String = lines[i].chars().skip(64).collect();
                lines[i] = format!("{:<64}{rest}", joined.chars().take(64).collect::<String>());
            }
            2 => {
                let i = self.below(lines.len());
                let mut b = lines[i].clone().into_bytes();
                if !b.is_empty() {
                    let at = self.below(b.len());
                    b[at] = b"0123456789,;-.EDH X"[self.below(19)];
                }
                lines[i] = String::from_utf8_lossy(&b).into_owned();
            }
            3 => {
                let i = self.below(lines.len());
                let copy = lines[i].clone();
                lines.insert(i, copy);
            }
            4 => {
                let i = self.below(lines.len());
                lines.remove(i);
            }
            _ => {
                let keep = self.below(lines.len());
                lines.truncate(keep);
            }
        }
        lines.join("\n") + "\n"
    }
}

#[test]
fn mutated_files_give_a_geometry_or_an_error_never_a_panic() {
    let start = std::time::Instant::now();
    let mut mutator = Mutator(0x5EED_1663);
    let mut errors = 0;
    let mut total = 0;
    for rel in [
        "formats/torus.igs",
        "formats/cylinder.igs",
        "sphere/sphere.igs",
        "naca0012/naca0012.igs",
    ] {
        let text = fixture(rel);
        for k in 0..1500 {
            // Up to three stacked mutations.
            let mut mutant = mutator.mutate(&text);
            for _ in 0..mutator.below(3) {
                mutant = mutator.mutate(&mutant);
            }
            let outcome = std::panic::catch_unwind(|| convert(&mutant).map(|_| ()));
            match outcome {
                Ok(Ok(())) => {}
                Ok(Err(_)) => errors += 1,
                Err(_) => panic!("{rel}, mutant {k} panicked:\n{mutant}"),
            }
            total += 1;
        }
    }
    // The mutations must bite: most mutants are rejected with an error.
    assert!(errors > total / 4, "{errors} errors of {total}");
    eprintln!(
        "{total} mutants, {errors} errors, {:.1} s",
        start.elapsed().as_secs_f64()
    );
}
