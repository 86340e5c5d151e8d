//! Every keyword of the `robot!` language, in one place, so that the parser, the
//! checks and the error messages ("valid keywords are ...") cannot drift apart.

use std::fmt;

/// One keyword of the DSL.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Symbol(pub &'static str);

// Top level.
pub const NAME: Symbol = Symbol("name");
pub const URDF: Symbol = Symbol("urdf");
pub const GRAVITY: Symbol = Symbol("gravity");
pub const INCIDENCE: Symbol = Symbol("incidence");
pub const JOINTS: Symbol = Symbol("joints");
pub const BODY_JOINT_VECTORS: Symbol = Symbol("body_joint_vectors");
pub const BODIES: Symbol = Symbol("bodies");
pub const FRAMES: Symbol = Symbol("frames");
/// Which functions to generate, in either form.
pub const FUNCTIONS: Symbol = Symbol("functions");

/// All top-level keywords, in the order the docs present them.
pub const TOP_LEVEL: &[Symbol] = &[
    NAME,
    URDF,
    GRAVITY,
    INCIDENCE,
    JOINTS,
    BODY_JOINT_VECTORS,
    BODIES,
    FRAMES,
    FUNCTIONS,
];
/// What the inline form needs besides `name`.
pub const INLINE_REQUIRED: &[Symbol] = &[INCIDENCE, JOINTS, BODY_JOINT_VECTORS, BODIES];
/// What the inline form may add.
pub const INLINE_OPTIONAL: &[Symbol] = &[GRAVITY, FRAMES];

// Joint types.
pub const REVOLUTE: Symbol = Symbol("revolute");
pub const CONTINUOUS: Symbol = Symbol("continuous");
pub const PRISMATIC: Symbol = Symbol("prismatic");
/// A ball joint, `spherical()`: no axis.
pub const SPHERICAL: Symbol = Symbol("spherical");
/// The free flyer of a floating base, `free()`: no axis; only between the base and
/// body 1.
pub const FREE: Symbol = Symbol("free");
/// Motion in the plane normal to the axis, `planar(z)`.
pub const PLANAR: Symbol = Symbol("planar");
pub const JOINT_TYPES: &[Symbol] = &[REVOLUTE, CONTINUOUS, PRISMATIC, PLANAR, SPHERICAL, FREE];
/// Not a joint type of the inline form; named only to explain why.
pub const FIXED: Symbol = Symbol("fixed");

// Named extras of a joint.
pub const REST: Symbol = Symbol("rest");
pub const LIMITS: Symbol = Symbol("limits");
pub const JOINT_OPTIONS: &[Symbol] = &[REST, LIMITS];
/// Named extras of a frame.
pub const FRAME_OPTIONS: &[Symbol] = &[REST];

// Axis names (joint axes may also be negated: `-x`).
pub const X: Symbol = Symbol("x");
pub const Y: Symbol = Symbol("y");
pub const Z: Symbol = Symbol("z");
pub const AXES: &[Symbol] = &[X, Y, Z];

// Body kinds and their named arguments.
pub const CYLINDER: Symbol = Symbol("cylinder");
pub const PRINCIPAL: Symbol = Symbol("principal");
pub const BODY_KINDS: &[Symbol] = &[CYLINDER, PRINCIPAL];
pub const MASS: Symbol = Symbol("mass");
pub const RADIUS: Symbol = Symbol("radius");
pub const LENGTH: Symbol = Symbol("length");
pub const AXIS: Symbol = Symbol("axis");
pub const MOMENTS: Symbol = Symbol("moments");
pub const CYLINDER_ARGS: &[Symbol] = &[MASS, RADIUS, LENGTH, AXIS];
pub const PRINCIPAL_ARGS: &[Symbol] = &[MASS, MOMENTS];

impl PartialEq<Symbol> for syn::Ident {
    fn eq(&self, word: &Symbol) -> bool {
        self == word.0
    }
}

impl fmt::Display for Symbol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

/// The symbol spelled `word`, if it is one of `symbols`.
pub fn lookup(symbols: &[Symbol], word: &syn::Ident) -> Option<Symbol> {
    symbols.iter().copied().find(|s| word == s)
}

/// "`a`, `b` or `c`", for messages that say what would be valid.
pub fn one_of(symbols: &[Symbol]) -> String {
    let quoted: Vec<String> = symbols.iter().map(|s| format!("`{s}`")).collect();
    match quoted.split_last() {
        None => String::new(),
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
    }
}

/// " (did you mean `bodies`?)" when `word` is a likely misspelling of one of
/// `symbols`, else the empty string.
pub fn did_you_mean(symbols: &[Symbol], word: &str) -> String {
    let best = symbols
        .iter()
        .map(|s| (edit_distance(word, s.0), s))
        .min_by_key(|(d, _)| *d);
    match best {
        // Short words are too easy to match by accident.
        Some((d, s)) if d > 0 && d <= 2 && d < s.0.len() / 2 + 1 => {
            format!(" (did you mean `{s}`?)")
        }
        _ => String::new(),
    }
}

/// Levenshtein distance on chars.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            let substitute = prev[j] + usize::from(ca != cb);
            cur[j + 1] = substitute.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_read_as_english() {
        assert_eq!(one_of(&[X]), "`x`");
        assert_eq!(one_of(&[X, Y, Z]), "`x`, `y` or `z`");
    }

    #[test]
    fn suggests_close_keywords_only() {
        assert_eq!(did_you_mean(TOP_LEVEL, "bodys"), " (did you mean `bodies`?)");
        assert_eq!(did_you_mean(TOP_LEVEL, "joint"), " (did you mean `joints`?)");
        assert_eq!(did_you_mean(TOP_LEVEL, "frame"), " (did you mean `frames`?)");
        assert_eq!(did_you_mean(TOP_LEVEL, "colour"), "");
        assert_eq!(did_you_mean(AXES, "w"), "");
    }
}
