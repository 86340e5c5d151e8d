//! Fuzzing on stable Rust: a small seeded mutator damages valid URDFs, `robot!`
//! descriptions and CSV logs (elements deleted, duplicated, swapped, numbers turned
//! into NaN, infinities, huge or negative values, text truncated, elements nested
//! deep) and each front end must answer with an error or a valid model, never a
//! panic, and never a non-finite number from a model or trajectory it accepted.
//!
//! `DYNGEN_FUZZ_CASES` sets the cases per front end (default 10,000);
//! `DYNGEN_FUZZ_SEED` the first seed (default 0), so a longer run explores new
//! inputs. A failure prints the seed and the input that caused it.

use dyngen_identify::data::Recipe;
use dyngen_model::Model;
use dyngen_reference::Reference;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::str::FromStr;

fn cases() -> u64 {
    std::env::var("DYNGEN_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000)
}

fn first_seed() -> u64 {
    std::env::var("DYNGEN_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0)
}

fn read(path: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Replacements for a number: the values that break naive numerics.
const BAD_NUMBERS: [&str; 16] = [
    "NaN", "inf", "-inf", "1e308", "-1e308", "1e400", "0", "-0", "-1", "-1e-3", "5e-324", "1e9", "abc", "", "1 2",
    "0x10",
];

/// Byte ranges of the numbers in `text` (digits with an optional sign, point and
/// exponent).
fn numbers(text: &str) -> Vec<std::ops::Range<usize>> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit() && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'));
        if !starts {
            i += 1;
            continue;
        }
        let start = if i > 0 && b[i - 1] == b'-' { i - 1 } else { i };
        let mut j = i;
        while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'.') {
            j += 1;
        }
        if j + 1 < b.len() && (b[j] == b'e' || b[j] == b'E') && (b[j + 1].is_ascii_digit() || b[j + 1] == b'-') {
            j += 2;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
        }
        out.push(start..j);
        i = j;
    }
    out
}

/// The largest char boundary at or below `k`.
fn floor_boundary(text: &str, mut k: usize) -> usize {
    k = k.min(text.len());
    while !text.is_char_boundary(k) {
        k -= 1;
    }
    k
}

/// Units a mutation works on: XML elements (start tag to end tag), or lines.
trait Units {
    fn units(text: &str) -> Vec<std::ops::Range<usize>>;
}

struct Elements;

impl Units for Elements {
    fn units(text: &str) -> Vec<std::ops::Range<usize>> {
        match dyngen_model::xml::scan(text) {
            Ok(tags) => tags.into_iter().skip(1).map(|t| t.span).collect(),
            Err(_) => Lines::units(text),
        }
    }
}

struct Lines;

impl Units for Lines {
    fn units(text: &str) -> Vec<std::ops::Range<usize>> {
        let mut out = Vec::new();
        let mut start = 0;
        for (k, c) in text.char_indices() {
            if c == '\n' {
                out.push(start..k + 1);
                start = k + 1;
            }
        }
        if start < text.len() {
            out.push(start..text.len());
        }
        out
    }
}

/// One random damage to `text`, working on units `U` (elements or lines); `open` and
/// `close` wrap a unit to nest it.
fn mutate<U: Units>(text: &str, rng: &mut ChaCha8Rng, open: &str, close: &str) -> String {
    let units = U::units(text);
    let pick = |rng: &mut ChaCha8Rng| units[rng.gen_range(0..units.len())].clone();
    match rng.gen_range(0..9) {
        // Delete a unit.
        0 if !units.is_empty() => {
            let r = pick(rng);
            format!("{}{}", &text[..r.start], &text[r.end..])
        }
        // Duplicate a unit.
        1 if !units.is_empty() => {
            let r = pick(rng);
            format!("{}{}{}", &text[..r.end], &text[r.clone()], &text[r.end..])
        }
        // Swap two units that do not overlap.
        2 if units.len() > 1 => {
            let (a, b) = (pick(rng), pick(rng));
            let (a, b) = if a.start <= b.start { (a, b) } else { (b, a) };
            if a.end > b.start {
                return text.to_string();
            }
            format!(
                "{}{}{}{}{}",
                &text[..a.start],
                &text[b.clone()],
                &text[a.end..b.start],
                &text[a.clone()],
                &text[b.end..]
            )
        }
        // Nest a unit: a few levels, or far past any limit.
        3 if !units.is_empty() => {
            let r = pick(rng);
            let depth = if rng.gen_bool(0.1) {
                rng.gen_range(200..400)
            } else {
                rng.gen_range(1..6)
            };
            format!(
                "{}{}{}{}{}",
                &text[..r.start],
                open.repeat(depth),
                &text[r.clone()],
                close.repeat(depth),
                &text[r.end..]
            )
        }
        // Truncate.
        4 => text[..floor_boundary(text, rng.gen_range(0..=text.len()))].to_string(),
        // Insert a stray character.
        5 => {
            let k = floor_boundary(text, rng.gen_range(0..=text.len()));
            let c = [
                "<", ">", "&", "\"", "'", "/", ",", ";", "\t", "\n", "[", "]", "{", "}", "é", "\0",
            ][rng.gen_range(0..16)];
            format!("{}{c}{}", &text[..k], &text[k..])
        }
        // Flip a number to a bad value, or scale it by a huge or negative factor.
        _ => {
            let found = numbers(text);
            if found.is_empty() {
                return text.to_string();
            }
            let r = found[rng.gen_range(0..found.len())].clone();
            let replacement = if rng.gen_bool(0.7) {
                BAD_NUMBERS[rng.gen_range(0..BAD_NUMBERS.len())].to_string()
            } else {
                let x: f64 = text[r.clone()].parse().unwrap_or(1.0);
                let factor = [-1.0, 1e6, 1e12, -1e-12, 1e300][rng.gen_range(0..5)];
                format!("{:e}", x * factor)
            };
            format!("{}{replacement}{}", &text[..r.start], &text[r.end..])
        }
    }
}

/// One to three damages.
fn damaged<U: Units>(seed_text: &str, rng: &mut ChaCha8Rng, open: &str, close: &str) -> String {
    let mut text = seed_text.to_string();
    for _ in 0..rng.gen_range(1..=3) {
        text = mutate::<U>(&text, rng, open, close);
    }
    text
}

/// A few states in `[-1, 1]` (fixed seed) at which an accepted model's inverse
/// dynamics must be finite, as must its parameters.
fn check_model(model: &Model) -> Result<(), String> {
    let params = model.standard_params();
    if let Some(k) = params.iter().position(|x| !x.is_finite()) {
        return Err(format!("standard parameter {k} is {}", params[k]));
    }
    let reference = Reference::new(model);
    // Coordinates as the model counts them (a follower of a <mimic> has none).
    let (nq, nv) = (model.nq(), model.nv());
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..3 {
        let mut state = |n: usize| (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect::<Vec<f64>>();
        let (q, v, a) = (state(nq), state(nv), state(nv));
        let tau = reference.rnea(&q, &v, &a, &params);
        if tau.iter().any(|x| !x.is_finite()) {
            return Err(format!("rnea({q:?}, {v:?}, {a:?}) = {tau:?}"));
        }
    }
    Ok(())
}

thread_local! {
    /// Set while this thread runs fuzz cases: their panics are caught and reported
    /// with the input, so the panic hook stays quiet for them.
    static FUZZING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Installs, once for the test binary, a panic hook that is silent on fuzzing
/// threads and the default one elsewhere (tests run on parallel threads).
fn quiet_panics_while_fuzzing() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !FUZZING.with(|f| f.get()) {
                default(info);
            }
        }));
    });
}

/// What one case came to.
#[derive(Default, Debug)]
struct Tally {
    accepted: u64,
    refused: u64,
}

impl Tally {
    /// Over a run of some size, more than `1/accepted` of the cases accepted and more
    /// than `1/refused` refused: damage that always or never breaks the input would
    /// leave a check idle.
    fn assert_mixed(&self, accepted: u64, refused: u64) {
        let total = self.accepted + self.refused;
        if total >= 1000 {
            assert!(
                self.accepted > total / accepted && self.refused > total / refused,
                "{self:?}"
            );
        }
    }
}

/// Runs `cases` inputs made from `seeds` by `make`, each through `front_end` under
/// `catch_unwind`: a panic, or an accepted input that fails `front_end`'s own
/// finiteness check, fails the test with the seed and the input.
fn fuzz(
    what: &str,
    (part, parts): (u64, u64),
    seeds: &[String],
    make: impl Fn(&str, &mut ChaCha8Rng) -> String,
    front_end: impl Fn(&str) -> Result<bool, String>,
) -> Tally {
    let mut tally = Tally::default();
    let per_part = cases().div_ceil(parts);
    let first = first_seed() + part * per_part;
    let last = (first_seed() + cases()).min(first + per_part);
    quiet_panics_while_fuzzing();
    FUZZING.with(|f| f.set(true));
    let mut failure = None;
    for case in first..last {
        let mut rng = ChaCha8Rng::seed_from_u64(case);
        let seed = &seeds[rng.gen_range(0..seeds.len())];
        let input = make(seed, &mut rng);
        match catch_unwind(AssertUnwindSafe(|| front_end(&input))) {
            Ok(Ok(true)) => tally.accepted += 1,
            Ok(Ok(false)) => tally.refused += 1,
            Ok(Err(why)) => failure = Some(format!("non-finite result: {why}")),
            Err(panic) => {
                let message = panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                failure = Some(format!("panic: {message}"));
            }
        }
        if let Some(f) = failure.take() {
            FUZZING.with(|f| f.set(false));
            let shown: String = input.chars().take(4000).collect();
            panic!("{what}, case {case} (DYNGEN_FUZZ_SEED={case} DYNGEN_FUZZ_CASES=1): {f}\ninput:\n{shown}");
        }
    }
    FUZZING.with(|f| f.set(false));
    eprintln!("{what}: cases {first}..{last}, {tally:?}");
    tally
}

fn urdf_seeds() -> Vec<String> {
    [
        "../robots/ur5/ur5.urdf",
        "../robots/panda/panda.urdf",
        "../robots/puma560/puma560.urdf",
        "../robots/gripper_arm/gripper_arm.urdf",
        "fixtures/planar2.urdf",
        "fixtures/paper6.urdf",
    ]
    .iter()
    .map(|p| read(p))
    .collect()
}

/// One part of the URDF cases: parsing is the slowest front end, so its cases are
/// split over tests that run in parallel.
fn fuzz_urdfs(part: u64) {
    let seeds = urdf_seeds();
    let tally = fuzz(
        "URDF",
        (part, URDF_PARTS),
        &seeds,
        |s, rng| damaged::<Elements>(s, rng, "<a>", "</a>"),
        |text| match dyngen_model::parse_urdf(text) {
            Ok(model) => check_model(&model).map(|()| true),
            Err(e) => {
                assert!(!e.errors.is_empty() && !e.to_string().is_empty());
                Ok(false)
            }
        },
    );
    // The mutations must leave some files valid, or the check of models is idle.
    tally.assert_mixed(20, 5);
}

const URDF_PARTS: u64 = 4;

#[test]
fn damaged_urdfs_give_errors_or_valid_models_1() {
    fuzz_urdfs(0);
}

#[test]
fn damaged_urdfs_give_errors_or_valid_models_2() {
    fuzz_urdfs(1);
}

#[test]
fn damaged_urdfs_give_errors_or_valid_models_3() {
    fuzz_urdfs(2);
}

#[test]
fn damaged_urdfs_give_errors_or_valid_models_4() {
    fuzz_urdfs(3);
}

/// The `robot!` invocations of the shipped DSL robots: the text between the braces.
fn dsl_seeds() -> Vec<String> {
    ["../robots/planar2/src/lib.rs", "../robots/paper6/src/lib.rs"]
        .iter()
        .map(|p| {
            let text = read(p);
            let start = text.find("dyngen::robot! {").expect("a robot! invocation") + "dyngen::robot! {".len();
            let end = text[start..].find("\n}").expect("its closing brace") + start;
            text[start..end].to_string()
        })
        .collect()
}

#[test]
fn damaged_dsl_inputs_give_errors_or_valid_models() {
    let seeds = dsl_seeds();
    let tally = fuzz(
        "robot! DSL",
        (0, 1),
        &seeds,
        |s, rng| damaged::<Lines>(s, rng, "[", "]"),
        |text| {
            // Text that is not even Rust tokens never reaches the macro.
            let Ok(tokens) = proc_macro2::TokenStream::from_str(text) else {
                return Ok(false);
            };
            match dyngen_codegen::dsl::parse(tokens) {
                Ok(input) => match input.source {
                    dyngen_codegen::RobotSource::Dsl(desc) => {
                        let model = desc
                            .build()
                            .map_err(|e| format!("parse accepted, build refused: {e:?}"))?;
                        check_model(&model).map(|()| true)
                    }
                    dyngen_codegen::RobotSource::Urdf(_) => Ok(false),
                },
                Err(e) => {
                    assert!(!e.to_string().is_empty());
                    Ok(false)
                }
            }
        },
    );
    tally.assert_mixed(20, 5);
}

/// A two-joint log in dyngen's schema, and the same with semicolons and a recipe
/// line of its own (the first line, split off before reading).
fn csv_seeds() -> Vec<String> {
    let mut rows = String::from("t,q1,q2,tau1,tau2\n");
    for k in 0..24 {
        let t = 0.01 * k as f64;
        rows.push_str(&format!(
            "{t},{},{},{},{}\n",
            (3.0 * t).sin(),
            0.5 * (2.0 * t).cos(),
            1.5 * (3.0 * t).cos(),
            -0.2 * t
        ));
    }
    let semicolons = format!("delimiter = semicolon\n{}", rows.replace(',', ";"));
    vec![format!("\n{rows}"), semicolons]
}

#[test]
fn damaged_csv_logs_give_errors_or_finite_trajectories() {
    let seeds = csv_seeds();
    let tally = fuzz(
        "CSV",
        (0, 1),
        &seeds,
        |s, rng| damaged::<Lines>(s, rng, "\"", "\""),
        |text| {
            let (recipe, csv) = text.split_once('\n').unwrap_or(("", text));
            let Ok(recipe) = Recipe::parse(recipe) else {
                return Ok(false);
            };
            let loaded = match recipe.read_from(csv.as_bytes(), None) {
                Ok(l) => l,
                Err(e) => {
                    assert!(!e.to_string().is_empty());
                    return Ok(false);
                }
            };
            let derived = match loaded.with_derivatives(10.0) {
                Ok(d) => d,
                Err(e) => {
                    assert!(!e.to_string().is_empty());
                    return Ok(false);
                }
            };
            let traj = &derived.trajectory;
            let all = [
                traj.t(),
                traj.positions(),
                traj.velocities().unwrap_or(&[]),
                traj.accelerations().unwrap_or(&[]),
                traj.torques(),
            ];
            for (name, values) in ["t", "q", "v", "a", "tau"].iter().zip(all) {
                if let Some(x) = values.iter().find(|x| !x.is_finite()) {
                    return Err(format!("{name} holds {x}"));
                }
            }
            Ok(true)
        },
    );
    tally.assert_mixed(20, 20);
}
