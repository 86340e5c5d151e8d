//! Tokens to the syntax tree ([`ast`](super::ast)). Lists are split at their
//! top-level commas and each element is parsed on its own, so one malformed element
//! records its error and parsing goes on with the next: the user sees every syntax
//! mistake at once. Errors at the end of an element point at that element (syn
//! would point at the whole macro call there).

use super::ast::{
    Attr, Axis, Body, BodyEntry, BodyTable, Entry, Frame, FrameEntry, FrameTable, Index, Joint, JointList, Limits,
    Matrix, Num, Robot, Row, Shape, Vector, VectorEntry, VectorTable,
};
use super::ctxt::{Ctxt, Loc};
use super::symbol::{self, Symbol};
use dyngen_model::JointKind;
use proc_macro2::{Delimiter, Group, Span, TokenStream, TokenTree};
use syn::ext::IdentExt;
use syn::parse::{ParseStream, Parser};
use syn::Token;

/// Parses a whole invocation. Never fails: problems go to `cx`.
pub fn robot(cx: &Ctxt, input: TokenStream) -> Robot {
    let mut robot = Robot {
        name: Attr::none(symbol::NAME),
        urdf: Attr::none(symbol::URDF),
        gravity: Attr::none(symbol::GRAVITY),
        incidence: Attr::none(symbol::INCIDENCE),
        joints: Attr::none(symbol::JOINTS),
        body_joint_vectors: Attr::none(symbol::BODY_JOINT_VECTORS),
        bodies: Attr::none(symbol::BODIES),
        frames: Attr::none(symbol::FRAMES),
        functions: Attr::none(symbol::FUNCTIONS),
    };
    for piece in nonempty_pieces(cx, input, "`keyword: value`") {
        let Some(field) = report(cx, key_value(piece.tokens, "keyword", symbol::TOP_LEVEL)) else {
            continue;
        };
        let KeyValue { key, value, loc } = field;
        let Some(word) = symbol::lookup(symbol::TOP_LEVEL, &key) else {
            cx.error_spanned_by(
                &key,
                format!(
                    "unknown keyword `{key}`{}; valid keywords are {}",
                    symbol::did_you_mean(symbol::TOP_LEVEL, &key.to_string()),
                    symbol::one_of(symbol::TOP_LEVEL)
                ),
            );
            continue;
        };
        match word {
            symbol::NAME => robot.name.set(cx, key, || report(cx, name(value))),
            symbol::URDF => robot.urdf.set(cx, key, || report(cx, urdf(value))),
            symbol::GRAVITY => robot
                .gravity
                .set(cx, key, || report(cx, parse_all(value, |i| vector(i, "gravity", loc)))),
            symbol::INCIDENCE => robot.incidence.set(cx, key, || incidence(cx, value, loc)),
            symbol::JOINTS => robot.joints.set(cx, key, || joints(cx, value, loc)),
            symbol::BODY_JOINT_VECTORS => robot
                .body_joint_vectors
                .set(cx, key, || body_joint_vectors(cx, value, loc)),
            symbol::BODIES => robot.bodies.set(cx, key, || bodies(cx, value, loc)),
            symbol::FRAMES => robot.frames.set(cx, key, || frames(cx, value, loc)),
            // symbol::FUNCTIONS, the last of TOP_LEVEL.
            _ => robot.functions.set(cx, key, || functions(cx, value, loc)),
        }
    }
    robot
}

impl<T> Attr<T> {
    /// Records the keyword and parses its value, unless the keyword was given before.
    fn set(&mut self, cx: &Ctxt, key: syn::Ident, value: impl FnOnce() -> Option<T>) {
        if self.key.is_some() {
            // Which of two values was meant is anyone's guess: report, keep the first.
            cx.error_spanned_by(
                &key,
                format!("duplicate `{}`; each keyword may appear once", self.symbol),
            );
            return;
        }
        self.key = Some(key);
        self.value = value();
    }
}

/// One comma-separated element of a list, with the comma that ends it.
struct Piece {
    tokens: TokenStream,
    comma: Option<Span>,
}

/// Splits at top-level commas (nested groups are single tokens). A trailing comma
/// is allowed; empty elements are kept so they can be reported.
fn split_commas(tokens: TokenStream) -> Vec<Piece> {
    let mut pieces = Vec::new();
    let mut current = TokenStream::new();
    for tt in tokens {
        match &tt {
            TokenTree::Punct(p) if p.as_char() == ',' => pieces.push(Piece {
                tokens: std::mem::take(&mut current),
                comma: Some(p.span()),
            }),
            _ => current.extend([tt]),
        }
    }
    if !current.is_empty() {
        pieces.push(Piece {
            tokens: current,
            comma: None,
        });
    }
    pieces
}

/// The non-empty elements; each empty one (`a,,b`) is reported at its comma.
fn nonempty_pieces(cx: &Ctxt, tokens: TokenStream, what: &str) -> Vec<Piece> {
    let mut out = Vec::new();
    for piece in split_commas(tokens) {
        if piece.tokens.is_empty() {
            let comma = piece.comma.unwrap_or_else(Span::call_site);
            cx.error_spanned_by(Loc::at(comma), format!("expected {what} before this comma"));
        } else {
            out.push(piece);
        }
    }
    out
}

/// Parses all of `tokens`; leftover tokens are an error at the first of them.
fn parse_all<T>(tokens: TokenStream, f: impl FnOnce(ParseStream) -> syn::Result<T>) -> syn::Result<T> {
    let whole = |input: ParseStream| {
        let value = f(input)?;
        if let Some((tt, _)) = input.cursor().token_tree() {
            // Most often two elements run together.
            let shown = match &tt {
                TokenTree::Group(g) => match g.delimiter() {
                    Delimiter::Parenthesis => "(..)".to_string(),
                    Delimiter::Bracket => "[..]".to_string(),
                    Delimiter::Brace => "{..}".to_string(),
                    Delimiter::None => "..".to_string(),
                },
                other => other.to_string(),
            };
            return Err(syn::Error::new_spanned(
                &tt,
                format!("unexpected `{shown}`; is a comma missing before it?"),
            ));
        }
        Ok(value)
    };
    whole.parse2(tokens)
}

/// Records the error, if any.
fn report<T>(cx: &Ctxt, result: syn::Result<T>) -> Option<T> {
    result.map_err(|e| cx.syn_error(e)).ok()
}

fn error(loc: Loc, msg: impl std::fmt::Display) -> syn::Error {
    syn::Error::new_spanned(loc, msg)
}

/// The range of what is left in `input`, or of `end` when nothing is.
fn rest_loc(input: ParseStream, end: Loc) -> Loc {
    let rest: TokenStream = input.fork().parse().unwrap_or_default();
    Loc::of(&rest, end.end)
}

struct KeyValue {
    key: syn::Ident,
    value: TokenStream,
    /// The whole `key: value`, for "this is incomplete" errors.
    loc: Loc,
}

/// `key: value...` where `value` is everything up to the end of the element.
fn key_value(tokens: TokenStream, what: &str, valid: &[Symbol]) -> syn::Result<KeyValue> {
    let loc = Loc::of(&tokens, Span::call_site());
    parse_all(tokens, |input| {
        let key = input.call(syn::Ident::parse_any).map_err(|_| {
            error(
                rest_loc(input, loc),
                format!("expected `{what}: value`; valid {what}s are {}", symbol::one_of(valid)),
            )
        })?;
        if !input.peek(Token![:]) {
            let found = rest_loc(input, Loc::at(key.span()));
            return Err(error(found, format!("expected `:` after `{key}`")));
        }
        let colon: Token![:] = input.parse()?;
        let value: TokenStream = input.parse()?;
        if value.is_empty() {
            return Err(error(
                Loc::at(key.span()).to(Loc::at(colon.span)),
                format!("expected a value after `{key}:`"),
            ));
        }
        Ok(KeyValue { key, value, loc })
    })
}

/// The next token, which must be a group with `delimiter`.
fn group(input: ParseStream, delimiter: Delimiter, what: &str, end: Loc) -> syn::Result<Group> {
    if input.is_empty() {
        return Err(error(end, format!("expected {what}")));
    }
    let tt: TokenTree = input.parse()?;
    match tt {
        TokenTree::Group(g) if g.delimiter() == delimiter => Ok(g),
        other => Err(syn::Error::new_spanned(other, format!("expected {what}"))),
    }
}

/// A whole value that must be one group with `delimiter`.
fn single_group(tokens: TokenStream, delimiter: Delimiter, what: &str, end: Loc) -> syn::Result<Group> {
    parse_all(tokens, |input| group(input, delimiter, what, end))
}

fn name(tokens: TokenStream) -> syn::Result<syn::Ident> {
    parse_all(tokens, |input| {
        input
            .parse::<syn::Ident>()
            .map_err(|_| input.error("expected the robot's type name, an identifier such as `Planar2`"))
    })
}

fn urdf(tokens: TokenStream) -> syn::Result<syn::LitStr> {
    parse_all(tokens, |input| {
        input.parse::<syn::LitStr>().map_err(|_| {
            input.error(
                "expected the URDF file as a string literal, such as \"robots/ur5.urdf\" \
                 (relative to the crate's Cargo.toml)",
            )
        })
    })
}

/// `-`? (integer | float). `what` names the expected number in messages.
fn number(input: ParseStream, what: &str, end: Loc) -> syn::Result<Num> {
    if input.is_empty() {
        return Err(error(end, format!("expected {what}")));
    }
    let minus: Option<Token![-]> = input.parse()?;
    if input.is_empty() {
        let at = minus.map_or(end, |m| Loc::at(m.span));
        return Err(error(at, format!("expected {what} after `-`")));
    }
    let lit: syn::Lit = input
        .parse()
        .map_err(|_| input.error(format!("expected {what}, a number such as 1, -0.5 or 1e-3")))?;
    let loc = match minus {
        Some(m) => Loc::at(m.span).to(Loc::at(lit.span())),
        None => Loc::at(lit.span()),
    };
    let (digits, int) = match &lit {
        syn::Lit::Int(i) => (i.base10_digits(), i.base10_parse::<i64>().ok()),
        syn::Lit::Float(f) => (f.base10_digits(), None),
        _ => return Err(error(loc, format!("expected {what}, a number such as 1, -0.5 or 1e-3"))),
    };
    let magnitude: f64 = digits
        .parse()
        .map_err(|_| error(loc, format!("expected {what}: `{digits}` is not a number")))?;
    // The one place that guarantees every number of the DSL is finite.
    if !magnitude.is_finite() {
        return Err(error(
            loc,
            format!("{digits} is too large for an f64; {what} must be finite"),
        ));
    }
    let (value, int) = if minus.is_some() {
        (-magnitude, int.map(|i| -i))
    } else {
        (magnitude, int)
    };
    Ok(Num { value, int, loc })
}

/// `[x, y, z]`.
fn vector(input: ParseStream, what: &str, end: Loc) -> syn::Result<Vector> {
    let g = group(input, Delimiter::Bracket, &format!("{what} as `[x, y, z]`"), end)?;
    let loc = Loc::at(g.span());
    let mut parts = Vec::new();
    for piece in split_commas(g.stream()) {
        if piece.tokens.is_empty() {
            let comma = piece.comma.map_or(loc, Loc::at);
            return Err(error(comma, "expected a number before this comma"));
        }
        let ploc = Loc::of(&piece.tokens, g.span());
        parts.push(parse_all(piece.tokens, |i| number(i, "a number", ploc))?);
    }
    match <[Num; 3]>::try_from(parts) {
        Ok(parts) => Ok(Vector { parts, loc }),
        Err(parts) => Err(error(
            loc,
            format!("{what} needs exactly 3 numbers `[x, y, z]`, found {}", parts.len()),
        )),
    }
}

/// An integer used as a body or joint number.
fn index(input: ParseStream, what: &str, end: Loc) -> syn::Result<Index> {
    let n = number(input, what, end)?;
    match n.int {
        Some(value) => Ok(Index { value, loc: n.loc }),
        None => Err(error(n.loc, format!("expected {what}, an integer"))),
    }
}

fn incidence(cx: &Ctxt, tokens: TokenStream, end: Loc) -> Option<Matrix> {
    const WHAT: &str = "the incidence matrix as a list of rows, `[[-1, 0], [1, -1], [0, 1]]`";
    let g = report(cx, single_group(tokens, Delimiter::Bracket, WHAT, end))?;
    let rows = nonempty_pieces(cx, g.stream(), "a row")
        .into_iter()
        .map(|piece| {
            let ploc = Loc::of(&piece.tokens, g.span());
            let row = report(
                cx,
                single_group(
                    piece.tokens,
                    Delimiter::Bracket,
                    "a row of the incidence matrix, such as `[1, -1, 0]`",
                    ploc,
                ),
            )?;
            let entries = nonempty_pieces(cx, row.stream(), "an entry")
                .into_iter()
                .map(|e| {
                    let eloc = Loc::of(&e.tokens, row.span());
                    let value = report(cx, parse_all(e.tokens, |i| number(i, "an entry", eloc))).and_then(|n| {
                        if n.int.is_none() {
                            cx.error_spanned_by(n.loc, "incidence entries are the integers -1, 0 or 1");
                        }
                        n.int
                    });
                    Entry { value, loc: eloc }
                })
                .collect();
            Some(Row {
                entries,
                loc: Loc::at(row.span()),
            })
        })
        .collect();
    Some(Matrix {
        rows,
        loc: Loc::at(g.span()),
    })
}

fn joints(cx: &Ctxt, tokens: TokenStream, end: Loc) -> Option<JointList> {
    let g = report(
        cx,
        single_group(
            tokens,
            Delimiter::Bracket,
            "the joints as a list, `[revolute(z), prismatic(x)]`",
            end,
        ),
    )?;
    let joints = nonempty_pieces(cx, g.stream(), "a joint")
        .into_iter()
        .map(|piece| joint(cx, piece.tokens))
        .collect();
    Some(JointList {
        joints,
        loc: Loc::at(g.span()),
    })
}

/// `[rnea, crba, frames]`: function or group names ([`crate::Capability::from_name`]).
fn functions(cx: &Ctxt, tokens: TokenStream, end: Loc) -> Option<crate::Selection> {
    let g = report(
        cx,
        single_group(
            tokens,
            Delimiter::Bracket,
            "the functions to generate as a list, `[rnea, crba, aba, frame_jacobian]`",
            end,
        ),
    )?;
    let mut selection = crate::Selection::empty();
    let mut valid = true;
    for piece in nonempty_pieces(cx, g.stream(), "a function") {
        let word = parse_all(piece.tokens, |input| {
            input.call(syn::Ident::parse_any).map_err(|_| {
                input.error(format!(
                    "expected a function or group name; {}",
                    crate::capability::valid_names()
                ))
            })
        });
        match report(cx, word) {
            Some(ident) => match crate::Capability::from_name(&ident.to_string()) {
                Some(c) => selection.insert(c),
                None => {
                    valid = false;
                    cx.error_spanned_by(&ident, crate::UnknownCapability(ident.to_string()).to_string());
                }
            },
            None => valid = false,
        }
    }
    if valid && selection.is_empty() {
        cx.error_spanned_by(
            Loc::at(g.span()),
            format!(
                "no function selected; list at least one, or leave `functions` out for all: {}",
                crate::capability::valid_names()
            ),
        );
    }
    valid.then_some(selection)
}

/// `revolute(AXIS, rest: [r, p, y], limits: [lo, hi])`.
fn joint(cx: &Ctxt, tokens: TokenStream) -> Option<Joint> {
    let valid = || {
        format!(
            "valid joint types are {}, each as `type(axis)` (the axis of `planar` is the plane normal; \
             `spherical()` and `free()` take no axis)",
            symbol::one_of(symbol::JOINT_TYPES)
        )
    };
    let head = parse_all(tokens, |input| {
        let kind = input
            .call(syn::Ident::parse_any)
            .map_err(|_| input.error(format!("expected a joint such as `revolute(z)`; {}", valid())))?;
        let args = group(
            input,
            Delimiter::Parenthesis,
            &format!("`(axis)` after `{kind}`, as in `{kind}(z)`"),
            Loc::at(kind.span()),
        )?;
        Ok((kind, args))
    });
    let (kind_ident, args) = report(cx, head)?;
    let kind_loc = Loc::at(kind_ident.span());
    let kind = match symbol::lookup(symbol::JOINT_TYPES, &kind_ident) {
        Some(symbol::REVOLUTE) => JointKind::Revolute,
        Some(symbol::CONTINUOUS) => JointKind::Continuous,
        Some(symbol::PRISMATIC) => JointKind::Prismatic,
        Some(symbol::SPHERICAL) => JointKind::Spherical,
        Some(symbol::FREE) => JointKind::FreeFlyer,
        Some(symbol::PLANAR) => JointKind::Planar,
        _ if kind_ident == symbol::FIXED => {
            cx.error_spanned_by(
                &kind_ident,
                format!(
                    "fixed joints are not available in the inline form: every column of the \
                     incidence matrix is a degree of freedom (describe the two bodies as one); {}",
                    valid()
                ),
            );
            return None;
        }
        _ => {
            cx.error_spanned_by(
                &kind_ident,
                format!(
                    "unknown joint type `{kind_ident}`{}; {}",
                    symbol::did_you_mean(symbol::JOINT_TYPES, &kind_ident.to_string()),
                    valid()
                ),
            );
            return None;
        }
    };
    let args_loc = Loc::at(args.span());
    let mut pieces = nonempty_pieces(cx, args.stream(), "an argument").into_iter().peekable();
    // `key: value`, as opposed to a positional axis.
    let named = |p: &Piece| {
        let mut t = p.tokens.clone().into_iter();
        matches!((t.next(), t.next()), (Some(TokenTree::Ident(_)), Some(TokenTree::Punct(c))) if c.as_char() == ':')
    };
    let axis = if !kind.has_axis() {
        // A ball joint or a free flyer turns (and moves) every way: no axis.
        if let Some(piece) = pieces.next_if(|p| !named(p)) {
            cx.error_spanned_by(
                Loc::of(&piece.tokens, args.span()),
                format!("a `{kind_ident}` joint has no axis: write `{kind_ident}()`"),
            );
        }
        None
    } else {
        match pieces.next() {
            None => {
                cx.error_spanned_by(
                    args_loc,
                    format!(
                        "expected the joint axis, as in `{kind_ident}(z)`: `x`, `y`, `z`, `-x`, `-y`, \
                     `-z` or `[ax, ay, az]`"
                    ),
                );
                None
            }
            Some(piece) => {
                let ploc = Loc::of(&piece.tokens, args.span());
                report(cx, parse_all(piece.tokens, |i| axis(i, ploc)))
            }
        }
    };
    let mut rest = None;
    let mut limits = None;
    for (key, word, value, vloc) in named_args(
        cx,
        pieces.collect(),
        symbol::JOINT_OPTIONS,
        &format!("`{kind_ident}` joint"),
    ) {
        if word == symbol::REST {
            rest = report(
                cx,
                parse_all(value, |i| vector(i, "the rest rotation `[roll, pitch, yaw]`", vloc)),
            );
        } else {
            limits = report(cx, parse_all(value, |i| limits_value(i, &key, vloc)));
        }
    }
    Some(Joint {
        kind,
        kind_loc,
        axis,
        rest,
        limits,
    })
}

/// `x`, `-y`, `[ax, ay, az]`.
fn axis(input: ParseStream, end: Loc) -> syn::Result<Axis> {
    const WHAT: &str = "the joint axis: `x`, `y`, `z`, `-x`, `-y`, `-z` or `[ax, ay, az]`";
    if input.peek(syn::token::Bracket) {
        let v = vector(input, "the joint axis", end)?;
        return Ok(Axis {
            value: v.value(),
            loc: v.loc,
        });
    }
    let minus: Option<Token![-]> = input.parse()?;
    if input.is_empty() {
        return Err(error(end, format!("expected {WHAT}")));
    }
    let ident = input
        .call(syn::Ident::parse_any)
        .map_err(|_| input.error(format!("expected {WHAT}")))?;
    let Some(k) = symbol::AXES.iter().position(|s| ident == *s) else {
        return Err(syn::Error::new_spanned(
            &ident,
            format!("unknown axis `{ident}`; expected {WHAT}"),
        ));
    };
    let sign = if minus.is_some() { -1.0 } else { 1.0 };
    let mut value = [0.0; 3];
    value[k] = sign;
    let loc = match minus {
        Some(m) => Loc::at(m.span).to(Loc::at(ident.span())),
        None => Loc::at(ident.span()),
    };
    Ok(Axis { value, loc })
}

/// `[lower, upper]`.
fn limits_value(input: ParseStream, key: &syn::Ident, end: Loc) -> syn::Result<Limits> {
    const WHAT: &str = "limits as `[lower, upper]`";
    let g = group(input, Delimiter::Bracket, WHAT, end)?;
    let loc = Loc::at(g.span());
    let mut parts = Vec::new();
    for piece in split_commas(g.stream()) {
        if piece.tokens.is_empty() {
            let comma = piece.comma.map_or(loc, Loc::at);
            return Err(error(comma, "expected a number before this comma"));
        }
        let ploc = Loc::of(&piece.tokens, g.span());
        parts.push(parse_all(piece.tokens, |i| number(i, "a limit", ploc))?);
    }
    match parts[..] {
        [lower, upper] => Ok(Limits {
            key_loc: Loc::at(key.span()),
            lower,
            upper,
            loc,
        }),
        _ => Err(error(
            loc,
            format!("expected {WHAT}: exactly 2 numbers, found {}", parts.len()),
        )),
    }
}

/// The `key: value` elements of an argument list: unknown, duplicate and malformed
/// ones are reported and dropped. Returns (key, which keyword, value, whole element).
fn named_args(
    cx: &Ctxt,
    pieces: Vec<Piece>,
    valid: &[Symbol],
    owner: &str,
) -> Vec<(syn::Ident, Symbol, TokenStream, Loc)> {
    let mut out: Vec<(syn::Ident, Symbol, TokenStream, Loc)> = Vec::new();
    for piece in pieces {
        let Some(KeyValue { key, value, loc }) = report(cx, key_value(piece.tokens, "argument", valid)) else {
            continue;
        };
        let Some(word) = symbol::lookup(valid, &key) else {
            cx.error_spanned_by(
                &key,
                format!(
                    "unknown argument `{key}` of a {owner}{}; valid arguments are {}",
                    symbol::did_you_mean(valid, &key.to_string()),
                    symbol::one_of(valid)
                ),
            );
            continue;
        };
        if out.iter().any(|(_, w, _, _)| *w == word) {
            cx.error_spanned_by(&key, format!("duplicate `{word}`; each argument may appear once"));
            continue;
        }
        out.push((key, word, value, loc));
    }
    out
}

/// `{ entry, ... }`, each entry parsed on its own so one bad entry does not hide
/// the others.
fn braced_entries<T>(
    cx: &Ctxt,
    tokens: TokenStream,
    end: Loc,
    expected: &str,
    entry: &str,
    parse: impl Fn(&Ctxt, TokenStream) -> Option<T>,
) -> Option<(Vec<T>, Loc)> {
    let g = report(cx, single_group(tokens, Delimiter::Brace, expected, end))?;
    let entries = nonempty_pieces(cx, g.stream(), entry)
        .into_iter()
        .filter_map(|piece| parse(cx, piece.tokens))
        .collect();
    Some((entries, Loc::at(g.span())))
}

fn body_joint_vectors(cx: &Ctxt, tokens: TokenStream, end: Loc) -> Option<VectorTable> {
    let (entries, loc) = braced_entries(
        cx,
        tokens,
        end,
        "the body-joint vectors as `{ (body, joint): [x, y, z], ... }`",
        "an entry `(body, joint): [x, y, z]`",
        vector_entry,
    )?;
    Some(VectorTable { entries, loc })
}

/// `(i, a): [x, y, z]`.
fn vector_entry(cx: &Ctxt, tokens: TokenStream) -> Option<VectorEntry> {
    let loc = Loc::of(&tokens, Span::call_site());
    let parsed = parse_all(tokens, |input| {
        let key = group(
            input,
            Delimiter::Parenthesis,
            "an entry `(body, joint): [x, y, z]`",
            loc,
        )?;
        let key_loc = Loc::at(key.span());
        let indices: Vec<Index> = split_commas(key.stream())
            .into_iter()
            .map(|p| {
                let ploc = Loc::of(&p.tokens, key.span());
                parse_all(p.tokens, |i| index(i, "a body or joint number", ploc))
            })
            .collect::<syn::Result<_>>()?;
        let [body, joint] = indices[..] else {
            return Err(error(
                key_loc,
                "expected `(body, joint)`: a body number and a joint number",
            ));
        };
        if !input.peek(Token![:]) {
            return Err(error(rest_loc(input, key_loc), "expected `:` after `(body, joint)`"));
        }
        input.parse::<Token![:]>()?;
        let value: TokenStream = input.parse()?;
        Ok((body, joint, key_loc, value))
    });
    let (body, joint, key_loc, value) = report(cx, parsed)?;
    let vector = report(cx, parse_all(value, |i| vector(i, "the body-joint vector", loc)));
    Some(VectorEntry {
        body,
        joint,
        key_loc,
        vector,
        loc,
    })
}

fn bodies(cx: &Ctxt, tokens: TokenStream, end: Loc) -> Option<BodyTable> {
    let (entries, loc) = braced_entries(
        cx,
        tokens,
        end,
        "the bodies as `{ 1: principal(mass: .., moments: [..]), ... }`",
        "a body `number: kind(...)`",
        body_entry,
    )?;
    Some(BodyTable { entries, loc })
}

/// `i: cylinder(...)` or `i: principal(...)`.
fn body_entry(cx: &Ctxt, tokens: TokenStream) -> Option<BodyEntry> {
    let loc = Loc::of(&tokens, Span::call_site());
    let kinds = || {
        format!(
            "valid body kinds are `cylinder({})` and `principal({})`",
            arg_list(symbol::CYLINDER_ARGS),
            arg_list(symbol::PRINCIPAL_ARGS)
        )
    };
    let parsed = parse_all(tokens, |input| {
        let index = index(input, "a body number", loc)?;
        if !input.peek(Token![:]) {
            return Err(error(rest_loc(input, index.loc), "expected `:` after the body number"));
        }
        input.parse::<Token![:]>()?;
        if input.is_empty() {
            return Err(error(loc, format!("expected a body; {}", kinds())));
        }
        let kind = input
            .call(syn::Ident::parse_any)
            .map_err(|_| input.error(format!("expected a body; {}", kinds())))?;
        let args = group(
            input,
            Delimiter::Parenthesis,
            &format!("`(...)` after `{kind}`"),
            Loc::at(kind.span()),
        )?;
        Ok((index, kind, args))
    });
    let (index, kind, args) = report(cx, parsed)?;
    let Some(word) = symbol::lookup(symbol::BODY_KINDS, &kind) else {
        cx.error_spanned_by(
            &kind,
            format!(
                "unknown body kind `{kind}`{}; {}",
                symbol::did_you_mean(symbol::BODY_KINDS, &kind.to_string()),
                kinds()
            ),
        );
        return Some(BodyEntry { index, body: None });
    };
    let valid = if word == symbol::CYLINDER {
        symbol::CYLINDER_ARGS
    } else {
        symbol::PRINCIPAL_ARGS
    };
    let pieces = nonempty_pieces(cx, args.stream(), "an argument");
    let given = named_args(cx, pieces, valid, &format!("`{kind}` body"));
    let get = |want: Symbol| -> Option<(TokenStream, Loc)> {
        let found = given
            .iter()
            .find(|(_, w, _, _)| *w == want)
            .map(|(_, _, v, l)| (v.clone(), *l));
        if found.is_none() {
            cx.error_spanned_by(
                &kind,
                format!("`{kind}` is missing `{want}`; it takes `{kind}({})`", arg_list(valid)),
            );
        }
        found
    };
    let num = |arg: Option<(TokenStream, Loc)>, what: &str| -> Option<Num> {
        let (value, vloc) = arg?;
        report(cx, parse_all(value, |i| number(i, what, vloc)))
    };
    let shape = if word == symbol::CYLINDER {
        let (mass, radius, length, axis) = (
            get(symbol::MASS),
            get(symbol::RADIUS),
            get(symbol::LENGTH),
            get(symbol::AXIS),
        );
        let mass = num(mass, "the mass in kg");
        let radius = num(radius, "the radius in m");
        let length = num(length, "the length in m");
        let axis = axis.and_then(|(value, vloc)| report(cx, parse_all(value, |i| cylinder_axis(i, vloc))));
        match (mass, radius, length, axis) {
            (Some(mass), Some(radius), Some(length), Some(axis)) => Some(Shape::Cylinder {
                mass,
                radius,
                length,
                axis,
            }),
            _ => None,
        }
    } else {
        let (mass, moments) = (get(symbol::MASS), get(symbol::MOMENTS));
        let mass = num(mass, "the mass in kg");
        let moments = moments.and_then(|(value, vloc)| {
            report(
                cx,
                parse_all(value, |i| vector(i, "the principal moments `[J1, J2, J3]`", vloc)),
            )
        });
        match (mass, moments) {
            (Some(mass), Some(moments)) => Some(Shape::Principal { mass, moments }),
            _ => None,
        }
    };
    Some(BodyEntry {
        index,
        body: shape.map(|shape| Body {
            shape,
            kind_loc: Loc::at(kind.span()),
        }),
    })
}

/// `x`, `y` or `z`: the body axis a cylinder's axis lies along.
fn cylinder_axis(input: ParseStream, end: Loc) -> syn::Result<(usize, Loc)> {
    let what = format!(
        "the cylinder's axis, one of the body axes {}",
        symbol::one_of(symbol::AXES)
    );
    if input.is_empty() {
        return Err(error(end, format!("expected {what}")));
    }
    let ident = input
        .call(syn::Ident::parse_any)
        .map_err(|_| input.error(format!("expected {what}")))?;
    match symbol::AXES.iter().position(|s| ident == *s) {
        Some(k) => Ok((k, Loc::at(ident.span()))),
        None => Err(syn::Error::new_spanned(
            &ident,
            format!("unknown axis `{ident}`; expected {what}"),
        )),
    }
}

fn frames(cx: &Ctxt, tokens: TokenStream, end: Loc) -> Option<FrameTable> {
    let (entries, _) = braced_entries(
        cx,
        tokens,
        end,
        "the frames as `{ tool: (2, [0.2, 0.0, 0.0]), ... }`",
        "a frame `name: (body, [x, y, z])`",
        frame_entry,
    )?;
    Some(FrameTable { entries })
}

/// `name: (i, [x, y, z])` or `name: (i, [x, y, z], rest: [r, p, y])`.
fn frame_entry(cx: &Ctxt, tokens: TokenStream) -> Option<FrameEntry> {
    let loc = Loc::of(&tokens, Span::call_site());
    let parsed = parse_all(tokens, |input| {
        let name = frame_name(input, loc)?;
        if !input.peek(Token![:]) {
            let found = rest_loc(input, Loc::at(name.span()));
            return Err(error(
                found,
                format!("expected `:` after the frame name `{name}`, as in `{name}: (body, [x, y, z])`"),
            ));
        }
        input.parse::<Token![:]>()?;
        let value: TokenStream = input.parse()?;
        Ok((name, value))
    });
    let (name, value) = report(cx, parsed)?;
    let frame = frame_value(cx, &name, value, loc);
    Some(FrameEntry { name, frame })
}

/// A frame's name: a plain identifier (it names a link, and may name generated items).
fn frame_name(input: ParseStream, end: Loc) -> syn::Result<syn::Ident> {
    const WHAT: &str = "the frame's name, an identifier such as `tool` or `camera_mount`";
    if input.is_empty() {
        return Err(error(end, format!("expected {WHAT}")));
    }
    let tt: TokenTree = input.fork().parse()?;
    match input.parse::<syn::Ident>() {
        Ok(ident) if !ident.to_string().starts_with("r#") => Ok(ident),
        _ => match &tt {
            // A keyword or a raw identifier.
            TokenTree::Ident(word) => Err(syn::Error::new_spanned(
                &tt,
                format!(
                    "`{word}` cannot name a frame: a frame's name is a plain identifier (not a Rust keyword, \
                     not raw), such as `tool` or `camera_mount`"
                ),
            )),
            _ => Err(syn::Error::new_spanned(&tt, format!("expected {WHAT}"))),
        },
    }
}

/// `(i, [x, y, z], rest: [r, p, y])` after `name:`.
fn frame_value(cx: &Ctxt, name: &syn::Ident, value: TokenStream, end: Loc) -> Option<Frame> {
    let form = format!(
        "a frame is `{name}: (body, [x, y, z])` or `{name}: (body, [x, y, z], {}: [roll, pitch, yaw])`: the \
         body's number (0 for the base), the frame's position from the body's centre of mass (from the base \
         origin for body 0) in the body's axes, and its rotation from those axes",
        symbol::REST
    );
    let args = report(
        cx,
        single_group(
            value,
            Delimiter::Parenthesis,
            &format!("`(body, [x, y, z])` after `{name}:`; {form}"),
            end,
        ),
    )?;
    let args_loc = Loc::at(args.span());
    let mut pieces = nonempty_pieces(cx, args.stream(), "an argument").into_iter();
    let Some(first) = pieces.next() else {
        cx.error_spanned_by(args_loc, format!("expected `(body, [x, y, z])`; {form}"));
        return None;
    };
    let ploc = Loc::of(&first.tokens, args.span());
    let body = report(
        cx,
        parse_all(first.tokens, |i| {
            index(i, "the number of the body the frame is fixed to", ploc)
        }),
    );
    let Some(second) = pieces.next() else {
        cx.error_spanned_by(
            args_loc,
            format!("expected the frame's position `[x, y, z]` after the body number; {form}"),
        );
        return None;
    };
    let ploc = Loc::of(&second.tokens, args.span());
    let position = report(
        cx,
        parse_all(second.tokens, |i| vector(i, "the frame's position", ploc)),
    );
    // Options only after a well-formed position: a position written without its
    // brackets would otherwise be reported once per number.
    let position = position?;
    let mut rest = None;
    for (_, _, value, vloc) in named_args(cx, pieces.collect(), symbol::FRAME_OPTIONS, "frame") {
        // `rest`, the only option.
        rest = report(
            cx,
            parse_all(value, |i| vector(i, "the rest rotation `[roll, pitch, yaw]`", vloc)),
        );
    }
    Some(Frame {
        body: body?,
        position,
        rest,
    })
}

/// "mass: .., radius: .."
fn arg_list(args: &[Symbol]) -> String {
    let parts: Vec<String> = args.iter().map(|a| format!("{a}: ..")).collect();
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use quote::quote;

    fn errors(input: TokenStream) -> Vec<String> {
        let cx = Ctxt::new();
        let _ = robot(&cx, input);
        match cx.check() {
            Ok(()) => Vec::new(),
            Err(e) => e.into_iter().map(|e| e.to_string()).collect(),
        }
    }

    fn num(tokens: TokenStream) -> syn::Result<Num> {
        parse_all(tokens, |i| number(i, "a number", Loc::at(Span::call_site())))
    }

    #[test]
    fn numbers_of_every_form() {
        assert_eq!(num(quote!(-1)).unwrap().int, Some(-1));
        assert_eq!(num(quote!(0.5)).unwrap().value, 0.5);
        assert_eq!(num(quote!(-9.81)).unwrap().value, -9.81);
        assert_eq!(num(quote!(1e-3)).unwrap().value, 1e-3);
        assert_eq!(num(quote!(-1e-3)).unwrap().int, None);
        assert!(num(quote!(1e999)).unwrap_err().to_string().contains("finite"));
        assert!(num(quote!(x)).is_err());
        let e = num(quote!(1 [2, 3])).unwrap_err().to_string();
        assert_eq!(e, "unexpected `[..]`; is a comma missing before it?");
        assert!(num(quote!(-)).is_err());
        assert_eq!(
            num(quote!(1 2)).unwrap_err().to_string(),
            "unexpected `2`; is a comma missing before it?"
        );
    }

    #[test]
    fn axes() {
        let ax = |t: TokenStream| parse_all(t, |i| axis(i, Loc::at(Span::call_site()))).map(|a| a.value);
        assert_eq!(ax(quote!(z)).unwrap(), [0.0, 0.0, 1.0]);
        assert_eq!(ax(quote!(-x)).unwrap(), [-1.0, 0.0, 0.0]);
        assert_eq!(ax(quote!([0, 0.6, -0.8])).unwrap(), [0.0, 0.6, -0.8]);
        assert!(ax(quote!(w)).is_err());
        assert!(ax(quote!([1, 0])).is_err());
    }

    #[test]
    fn splitting_keeps_empty_elements_and_drops_a_trailing_comma() {
        let pieces = split_commas(quote!(a, , b(1, 2),));
        let texts: Vec<String> = pieces.iter().map(|p| p.tokens.to_string()).collect();
        assert_eq!(texts, ["a", "", "b (1 , 2)"]);
    }

    #[test]
    fn syntax_errors_are_all_collected() {
        let e = errors(quote! {
            name: "Planar",
            colour: red,
            gravity: [0.0, 1.0],
            joints: [revolute(w), helical(z), revolute(z, rest: [0, 0, 0], rest: [0, 0, 0])],
            bodies: { 1: cylinder(mass: 1.0, radius: 0.1, axis: x), 2: blob() },
        });
        assert_eq!(e.len(), 8, "{e:#?}");
        assert!(e[0].contains("type name"));
        assert!(e[1].contains("unknown keyword `colour`"));
        assert!(e[2].contains("exactly 3 numbers"));
        assert!(e[3].contains("unknown axis `w`"));
        assert!(e[4].contains("unknown joint type `helical`"));
        assert!(e[5].contains("duplicate `rest`"));
        assert!(e[6].contains("missing `length`"), "{e:#?}");
        assert!(e[7].contains("unknown body kind `blob`"), "{e:#?}");
    }

    #[test]
    fn unknown_body_kind_is_reported() {
        let e = errors(quote!(bodies: { 1: blob() }));
        assert_eq!(e.len(), 1, "{e:#?}");
        assert!(e[0].contains("unknown body kind `blob`"));
    }

    #[test]
    fn frames_parse() {
        let cx = Ctxt::new();
        let r = robot(
            &cx,
            quote!(frames: { tool: (2, [0.2, 0, -1e-3]), camera: (1, [0, 0.05, 0], rest: [0, 0, 1.5],) }),
        );
        cx.check().unwrap();
        let frames = &r.frames.value.unwrap().entries;
        let tool = frames[0].frame.as_ref().unwrap();
        assert_eq!(frames[0].name, "tool");
        assert_eq!((tool.body.value, tool.position.value()), (2, [0.2, 0.0, -1e-3]));
        assert!(tool.rest.is_none());
        let camera = frames[1].frame.as_ref().unwrap();
        assert_eq!(frames[1].name, "camera");
        assert_eq!(camera.body.value, 1);
        assert_eq!(camera.rest.unwrap().value(), [0.0, 0.0, 1.5]);
    }

    #[test]
    fn frame_syntax_errors_are_all_collected() {
        let e = errors(quote! {
            frames: {
                "tool": (2, [0, 0, 0]),
                type: (2, [0, 0, 0]),
                r#tool: (2, [0, 0, 0]),
                tool (2, [0, 0, 0]),
                a: [2, 0, 0, 0],
                b: (2),
                c: (2, 0.1, 0.0, 0.0),
                d: (2.5, [0, 0]),
                e: (2, [0, 0, 0], rset: [0, 0, 0], rest: [0, 0]),
                f: (),
            },
        });
        let want = [
            "expected the frame's name, an identifier such as `tool`",
            "`type` cannot name a frame",
            "`r#tool` cannot name a frame",
            "expected `:` after the frame name `tool`",
            "expected `(body, [x, y, z])` after `a:`; a frame is `a: (body, [x, y, z])` or",
            "expected the frame's position `[x, y, z]` after the body number",
            "expected the frame's position as `[x, y, z]`",
            "expected the number of the body the frame is fixed to, an integer",
            "the frame's position needs exactly 3 numbers",
            "unknown argument `rset` of a frame (did you mean `rest`?); valid arguments are `rest`",
            "the rest rotation `[roll, pitch, yaw]` needs exactly 3 numbers",
            "expected `(body, [x, y, z])`; a frame is `f: (body, [x, y, z])` or",
        ];
        assert_eq!(e.len(), want.len(), "{e:#?}");
        for (got, want) in e.iter().zip(want) {
            assert!(got.contains(want), "{got:?} should contain {want:?}");
        }
    }

    #[test]
    fn duplicate_keyword() {
        let e = errors(quote!(name: A, name: B));
        assert_eq!(e.len(), 1);
        assert!(e[0].starts_with("duplicate `name`"), "{e:?}");
    }
}
