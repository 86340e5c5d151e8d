//! The middle layer: a checked model and its base parameters in, the robot type's
//! tokens out, no I/O. The macro, `build.rs` and the command line all call
//! [`crate::base::analyse_model`] and then [`generate`].
//!
//! Every generated algorithm is one entry of [`ALGORITHMS`]: its inherent function,
//! its capability trait's method and its line in `OP_COUNTS` are all made from that entry.

use crate::algo::{self, Force, Inputs, ARG_A, ARG_JOINT_PARAMS, ARG_PARAMS, ARG_Q, ARG_TAU, ARG_V};
use crate::base::{BaseParams, Bases};
use crate::capability::{Capability, Selection};
use crate::emit::{self, Arg, FnReport, FnSpec, Output};
use crate::mimic::Block;
use crate::sym::{Expr, Graph, NodeId};
use dyngen_model::Model;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// Options of the generator.
#[derive(Clone, Debug)]
pub struct Options {
    /// Statements per emitted function before it is split into parts.
    pub max_statements: usize,
    /// A robot with more velocity coordinates than this gets functions composed of
    /// other generated functions where a graph of their own would repeat another
    /// one's code ([`DEFAULT_COMPOSE_ABOVE_NV`]).
    pub compose_above_nv: usize,
    /// The capability traits to generate (default all); what their functions are
    /// built from comes with them ([`Selection::closure`]).
    pub functions: Selection,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_statements: emit::DEFAULT_MAX_STATEMENTS,
            compose_above_nv: DEFAULT_COMPOSE_ABOVE_NV,
            functions: Selection::all(),
        }
    }
}

/// The generated robot type and what went into it.
pub struct GeneratedCode {
    pub tokens: TokenStream,
    pub functions: Vec<FnReport>,
    /// Each associated function of the robot type on its own, by name.
    pub items: Vec<(String, TokenStream)>,
    /// The bodies of the generated functions (with their parts, see
    /// [`emit::Emitted`]), by name.
    pub bodies: Vec<(String, TokenStream)>,
    /// `tokens` in the pieces [`GeneratedCode::pretty`] formats apart: the robot type
    /// before the bodies' module, the frame enum after it, and that module's name.
    head: TokenStream,
    tail: TokenStream,
    home: proc_macro2::Ident,
}

/// The module of the generated bodies (see [`emit::home`]), holding `bodies`.
fn home_module<'a>(home: &proc_macro2::Ident, bodies: impl Iterator<Item = &'a TokenStream>) -> TokenStream {
    quote! {
        #[doc(hidden)]
        #[allow(non_snake_case, clippy::all, clippy::pedantic, unused_variables, unused_parens)]
        mod #home {
            #(#bodies)*
        }
    }
}

/// Formats one piece of Rust source, with a comment where each marked section starts.
fn format_piece(text: &str) -> Option<String> {
    let file = syn::parse_file(text).ok()?;
    Some(emit::comment_markers(&prettyplease::unparse(&file)))
}

/// Pieces of source formatted on up to `threads` threads, in order.
fn format_pieces(texts: &[String], threads: usize) -> Vec<Option<String>> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut done: Vec<(usize, Option<String>)> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads.clamp(1, texts.len().max(1)))
            .map(|_| {
                s.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(text) = texts.get(k) else { break mine };
                        mine.push((k, format_piece(text)));
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            // A panic while formatting is a bug; it is carried over as it was.
            .flat_map(|w| w.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    done.sort_by_key(|(k, _)| *k);
    done.into_iter().map(|(_, f)| f).collect()
}

/// The lines of a formatted module between its opening line (`mod name {`, after its
/// attributes) and its closing brace: `(attributes and opening line, inside)`.
fn split_module(formatted: &str) -> Option<(&str, &str)> {
    let open = formatted.find("\nmod ")? + 1;
    let inside = open + formatted[open..].find('\n')? + 1;
    let close = formatted.trim_end().rfind('\n')? + 1;
    (formatted[close..].trim_end() == "}" && close >= inside).then(|| (&formatted[..inside], &formatted[inside..close]))
}

/// One module from its pieces, each formatted as the module holding some of its
/// items: the first piece's attributes and opening line, every piece's inside, the
/// closing brace.
fn join_module(pieces: &[String]) -> Option<String> {
    let mut out = String::new();
    for (k, piece) in pieces.iter().enumerate() {
        let (opening, inside) = split_module(piece)?;
        if k == 0 {
            out.push_str(opening);
        }
        out.push_str(inside);
    }
    out.push_str("}\n");
    Some(out)
}

impl GeneratedCode {
    /// The code formatted with prettyplease, as written to files and snapshots, with
    /// a comment where each section (e.g. a body's step of a recursion) starts.
    ///
    /// Formatting is most of what generating a large tree costs (the 31-joint
    /// humanoid's 225k lines: 1.6 s of 2.9 s), so the robot type, the frame enum and
    /// the bodies' module in pieces of about equal size are formatted on threads of
    /// their own, from their text (token streams do not leave the thread that made
    /// them), and put together: the same file as the whole formatted at once.
    pub fn pretty(&self) -> String {
        const PIECES: usize = 8;
        let bodies: Vec<String> = self.bodies.iter().map(|(_, b)| b.to_string()).collect();
        let total: usize = bodies.iter().map(String::len).sum();
        // The module's text up to its closing brace, which each piece puts after its bodies.
        let empty = home_module(&self.home, std::iter::empty()).to_string();
        let opening = empty.trim_end().strip_suffix('}').unwrap_or(&empty);
        let mut texts = vec![self.head.to_string(), self.tail.to_string()];
        let mut piece = String::from(opening);
        for (k, body) in bodies.iter().enumerate() {
            piece.push_str(body);
            if (piece.len() - opening.len()) * PIECES >= total || k + 1 == bodies.len() {
                piece.push('}');
                texts.push(std::mem::replace(&mut piece, String::from(opening)));
            }
        }
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let formatted: Option<Vec<String>> = format_pieces(&texts, threads).into_iter().collect();
        let assembled = formatted.and_then(|f| {
            let module = match &f[2..] {
                [] => format_piece(&empty)?,
                pieces => join_module(pieces)?,
            };
            Some(format!("{}{module}{}", f[0], f[1]))
        });
        assembled.unwrap_or_else(|| self.tokens.to_string())
    }

    /// The generated file: a header naming `source` and saying not to edit it, then
    /// [`GeneratedCode::pretty`].
    pub fn file(&self, source: &str) -> String {
        format!(
            "// @generated by dyngen-codegen from {source}; do not edit.\n{}",
            self.pretty()
        )
    }

    /// One function, formatted, inside an `impl` of the robot type, followed by its
    /// body's module if it has one.
    pub fn pretty_function(&self, name: &str) -> Option<String> {
        let (_, tokens) = self.items.iter().find(|(n, _)| n == name)?;
        let body = self.bodies.iter().find(|(n, _)| n == name).map(|(_, t)| t);
        let file = syn::parse2::<syn::File>(quote!(impl Robot { #tokens } #body)).ok()?;
        Some(emit::comment_markers(&prettyplease::unparse(&file)))
    }

    /// One line per function: name, operation counts, statements.
    pub fn op_report(&self) -> String {
        let mut s = String::new();
        for f in &self.functions {
            s.push_str(&format!(
                "{:<26} {:>6} mul {:>3} div {:>6} add {:>5} neg {:>3} trig {:>6} statements{}\n",
                f.name,
                f.ops.muls,
                f.ops.divs,
                f.ops.adds,
                f.ops.negs,
                f.ops.trig,
                f.statements,
                if f.parts > 1 {
                    format!(" in {} parts", f.parts)
                } else {
                    String::new()
                }
            ));
        }
        s
    }
}

/// Whether `name` can name the generated type.
pub fn is_type_name(name: &str) -> bool {
    syn::parse_str::<syn::Ident>(name).is_ok()
}

/// A regressor as output nodes, structural zeros as the constant 0.
fn matrix_ids<'g>(g: &'g Graph, y: &[Vec<Option<Expr<'g>>>]) -> Vec<NodeId> {
    y.iter()
        .flat_map(|row| row.iter().map(|e| e.unwrap_or_else(|| g.zero()).id()))
        .collect()
}

/// The columns `keep` of a regressor, as output nodes.
fn columns_ids<'g>(g: &'g Graph, y: &[Vec<Option<Expr<'g>>>], keep: &[usize]) -> Vec<NodeId> {
    let cols: Vec<Vec<Option<Expr<'g>>>> = y.iter().map(|row| keep.iter().map(|&c| row[c]).collect()).collect();
    matrix_ids(g, &cols)
}

fn force_ids(forces: &[Force<'_>]) -> Vec<NodeId> {
    forces
        .iter()
        .flat_map(|w| w.f.0.iter().chain(w.n.0.iter()).map(|e| e.id()))
        .collect()
}

/// `β = K · x` as straight-line code over the argument `x`; with `joints`, columns
/// from `joints` on are read from `joint_params` (`x = [params; joint_params]`).
fn base_params_ids(g: &Graph, bp: &BaseParams, joints: Option<usize>) -> Vec<NodeId> {
    let input = |c: usize| match joints {
        Some(first) if c >= first => g.input(ARG_JOINT_PARAMS, (c - first) as u32),
        _ => g.input(ARG_PARAMS, c as u32),
    };
    bp.k.iter()
        .map(|row| {
            row.iter()
                .enumerate()
                .filter(|(_, &x)| x != 0.0)
                .fold(g.zero(), |acc, (c, &x)| acc + g.constant(x) * input(c))
                .id()
        })
        .collect()
}

/// The sizes a generated robot's signatures and docs are written with.
pub(crate) struct Sizes {
    /// Joints = moving bodies.
    pub(crate) n: usize,
    /// Position and velocity coordinates (equal to `n` when every joint has one
    /// degree of freedom).
    pub(crate) nq: usize,
    pub(crate) nv: usize,
    /// Base parameters of the standard and the principal parameterisation, and of
    /// the standard and joint parameters together.
    pub(crate) nb: usize,
    pub(crate) nbt: usize,
    pub(crate) nbj: usize,
}

impl Sizes {
    fn of(&self, len: Len) -> usize {
        match len {
            Len::Q => self.nq,
            Len::V => self.nv,
            Len::Params => 10 * self.n,
            Len::Theta => 4 * self.n,
            Len::Base => self.nb,
            Len::PrincipalBase => self.nbt,
            Len::WrenchRows => 6 * self.n,
            Len::JointParams => 4 * self.nv,
            Len::BaseJoints => self.nbj,
        }
    }

    pub(crate) fn state(&self) -> String {
        if self.nq == self.nv {
            format!(
                "`q, v, a`: {} joint positions (rad or m), velocities, accelerations",
                self.n
            )
        } else {
            format!(
                "`q`: {} positions (a unit quaternion `[x, y, z, w]` per ball joint and free flyer);
`v, a`: {} velocities and accelerations",
                self.nq, self.nv
            )
        }
    }

    pub(crate) fn params(&self) -> String {
        format!(
            "`params`: {} standard parameters, 10 per body (`Self::NOMINAL_PARAMS` for the description's)",
            10 * self.n
        )
    }

    pub(crate) fn joint_params(&self) -> String {
        format!(
            "`joint_params`: {} joint parameters `[Ia, Fv, Fc, F0]`, 4 per velocity coordinate (`Self::NOMINAL_JOINT_PARAMS` for the description's)",
            4 * self.nv
        )
    }
}

/// A length in a generated signature, in terms of the robot's sizes.
#[derive(Clone, Copy)]
enum Len {
    /// `nq` positions.
    Q,
    /// `nv` velocities (rows of the dynamics).
    V,
    Params,
    Theta,
    Base,
    PrincipalBase,
    /// `6 n`: a `[force; moment]` row block per joint.
    WrenchRows,
    /// `4 n`: `[Ia, Fv, Fc, F0]` per joint.
    JointParams,
    BaseJoints,
}

/// An argument of a generated function (`&[S; len]` in the inherent function, `&[S]`
/// in the capability trait's method).
#[derive(Clone, Copy)]
enum In {
    Q,
    V,
    A,
    Tau,
    Params,
    Theta,
    JointParams,
}

impl In {
    fn arg(self, sizes: &Sizes) -> Arg {
        let (id, name, len) = match self {
            In::Q => (ARG_Q, "q", Len::Q),
            In::V => (ARG_V, "v", Len::V),
            In::A => (ARG_A, "a", Len::V),
            In::Tau => (ARG_TAU, "tau", Len::V),
            In::Params => (ARG_PARAMS, "params", Len::Params),
            In::Theta => (ARG_PARAMS, "theta", Len::Theta),
            In::JointParams => (ARG_JOINT_PARAMS, "joint_params", Len::JointParams),
        };
        Arg {
            id,
            name,
            len: sizes.of(len),
        }
    }
}

/// A `dyngen` type returned per body, built from a fixed number of outputs.
#[derive(Clone, Copy)]
pub(crate) enum Record {
    Pose,
    Wrench,
    BodyRegressor,
}

impl Record {
    pub(crate) fn ty(self) -> TokenStream {
        match self {
            Record::Pose => quote!(::dyngen::Pose<S>),
            Record::Wrench => quote!(::dyngen::Wrench<S>),
            Record::BodyRegressor => quote!(::dyngen::BodyRegressor<S>),
        }
    }

    fn outputs(self) -> usize {
        match self {
            Record::Pose => 12,
            Record::Wrench => 6,
            Record::BodyRegressor => 24,
        }
    }

    pub(crate) fn build(self, c: &[TokenStream]) -> TokenStream {
        match self {
            Record::Pose => {
                let (r, t) = (&c[..9], &c[9..]);
                quote!(::dyngen::Pose {
                    rotation: ::dyngen::nalgebra::Matrix3::new(#(#r),*),
                    translation: ::dyngen::nalgebra::Vector3::new(#(#t),*),
                })
            }
            Record::Wrench => {
                let (f, m) = (&c[..3], &c[3..]);
                quote!(::dyngen::Wrench {
                    force: ::dyngen::nalgebra::Vector3::new(#(#f),*),
                    torque: ::dyngen::nalgebra::Vector3::new(#(#m),*),
                })
            }
            Record::BodyRegressor => {
                let (f, m) = (&c[..12], &c[12..]);
                quote!(::dyngen::BodyRegressor {
                    force: ::dyngen::nalgebra::SMatrix::<S, 3, 4>::new(#(#f),*),
                    moment: ::dyngen::nalgebra::SMatrix::<S, 3, 4>::new(#(#m),*),
                })
            }
        }
    }
}

/// What a generated function hands back, and so how the trait method's output
/// slice maps onto it.
#[derive(Clone, Copy)]
enum Shape {
    /// `[S; len]`, returned; the trait method writes it into a slice of that length.
    Vector(Len),
    /// One record per body, `[T; n]`, returned.
    PerBody(Record),
    /// `[[S; cols]; rows]`, written through `out`; the trait method takes it row-major.
    Matrix { rows: Len, cols: Len },
}

/// One generated algorithm: everything the inherent function, the trait method
/// and the operation counts are made from. Adding an algorithm is adding an entry
/// to [`ALGORITHMS`] (and its method to its capability trait in `dyngen`).
struct Algorithm {
    name: &'static str,
    /// Arguments in signature order.
    args: &'static [In],
    /// The name of the trait method's output slice.
    out: &'static str,
    shape: Shape,
    /// The doc text, one paragraph line per line.
    doc: fn(&Sizes) -> String,
    /// Builds the outputs in a fresh graph, so each function's operation count is
    /// its own. Outputs are row-major for matrices, in record order per body.
    build: for<'g> fn(&'g Graph, &Model, &Bases) -> Vec<NodeId>,
}

/// The statement budget of a part of the regressor functions. They are long
/// (the humanoid's joint wrench regressor has 9,143 statements, its joint torque
/// regressor 6,955) and serve identification, where a sample's cost matters less
/// than a control loop's: kept in parts of 1,200, they build 2 s faster on the
/// humanoid than whole.
const REGRESSOR_MAX_STATEMENTS: usize = 1200;

impl Algorithm {
    /// The capability trait it belongs to: the one whose functions name it.
    fn capability(&self) -> Capability {
        // ok: every ALGORITHMS name is a trait function (test `every_algorithm_has_a_capability`).
        Capability::from_name(self.name).expect("an ALGORITHMS entry named after a trait function")
    }

    fn max_statements(&self, options: &Options) -> usize {
        if self.name.ends_with("regressor") || self.name.ends_with("regressors") {
            options.max_statements.min(REGRESSOR_MAX_STATEMENTS)
        } else {
            options.max_statements
        }
    }
}

const QVA: &[In] = &[In::Q, In::V, In::A];
const QVAP: &[In] = &[In::Q, In::V, In::A, In::Params];

/// Every generated algorithm, in the order they are emitted and reported.
const ALGORITHMS: &[Algorithm] = &[
    Algorithm {
        name: "rnea",
        args: QVAP,
        out: "tau",
        shape: Shape::Vector(Len::V),
        doc: |s| {
            format!(
                "Inverse dynamics, `tau = M(q) a + C(q, v) v + g(q)`, by the unrolled Newton–Euler\nrecursion. {};\n{}. Returns the {} joint torques (N·m) or forces (N).",
                s.state(),
                s.params(),
                s.nv
            )
        },
        build: |g, model, _| algo::rnea(g, model, Inputs::Full).tau.iter().map(|x| x.id()).collect(),
    },
    Algorithm {
        name: "nonlinear_effects",
        args: &[In::Q, In::V, In::Params],
        out: "tau",
        shape: Shape::Vector(Len::V),
        doc: |s| {
            format!(
                "Coriolis, centrifugal and gravity terms `h(q, v) = C(q, v) v + g(q)`, equal to\n`rnea(q, v, 0)`. {}.",
                s.params()
            )
        },
        build: |g, model, _| {
            algo::rnea(g, model, Inputs::NoAcceleration)
                .tau
                .iter()
                .map(|x| x.id())
                .collect()
        },
    },
    Algorithm {
        name: "generalized_gravity",
        args: &[In::Q, In::Params],
        out: "tau",
        shape: Shape::Vector(Len::V),
        doc: |s| format!("Gravity torques `g(q)`, equal to `rnea(q, 0, 0)`. {}.", s.params()),
        build: |g, model, _| {
            algo::rnea(g, model, Inputs::Static)
                .tau
                .iter()
                .map(|x| x.id())
                .collect()
        },
    },
    Algorithm {
        name: "forward_kinematics",
        args: &[In::Q],
        out: "poses",
        shape: Shape::PerBody(Record::Pose),
        doc: |s| {
            format!(
                "Every body's pose in the base frame, body 1 first: `x_base = rotation · x_body +\ntranslation`. `q`: {} joint positions.",
                s.nq
            )
        },
        build: |g, model, _| {
            algo::forward_kinematics(g, model)
                .iter()
                .flat_map(|(r, t)| r.0.iter().flatten().chain(t.0.iter()).map(|x| x.id()))
                .collect()
        },
    },
    Algorithm {
        name: "joint_wrenches",
        args: QVAP,
        out: "wrenches",
        shape: Shape::PerBody(Record::Wrench),
        doc: |s| {
            format!(
                "The reaction wrench each joint applies to its outboard body: for joint `j`, the\nforce (N) and the moment (N·m) about the joint-frame origin, in body `j`'s frame\n(Pinocchio's `data.f[j]` after `rnea`). Arguments as for [`Self::rnea`]; returns {}\nwrenches, joint 1 first.",
                s.n
            )
        },
        build: |g, model, _| force_ids(&algo::rnea(g, model, Inputs::Full).wrenches),
    },
    Algorithm {
        name: "crba",
        args: &[In::Q, In::Params],
        out: "m",
        shape: Shape::Matrix {
            rows: Len::V,
            cols: Len::V,
        },
        doc: |s| {
            format!(
                "The joint-space inertia matrix `M(q)` ({n} × {n}, symmetric positive definite) by the\ncomposite-rigid-body algorithm; entries of joints on different branches are not\ncomputed. {}.",
                s.params(),
                n = s.nv
            )
        },
        build: |g, model, _| algo::crba(g, model).iter().flatten().map(|x| x.id()).collect(),
    },
    Algorithm {
        name: "aba",
        args: &[In::Q, In::V, In::Tau, In::Params],
        out: "a",
        shape: Shape::Vector(Len::V),
        doc: |s| {
            format!(
                "Forward dynamics, `a = M(q)⁻¹ (tau − h(q, v))`, by the articulated-body algorithm.\n`q, v, tau`: {n} positions, velocities, joint torques or forces; {}.\nReturns the {n} joint accelerations; `aba(q, v, rnea(q, v, a)) = a`.",
                s.params(),
                n = s.nv
            )
        },
        build: |g, model, _| {
            algo::aba(g, model, algo::Armature::None)
                .iter()
                .map(|x| x.id())
                .collect()
        },
    },
    Algorithm {
        name: "joint_torque_regressor",
        args: QVA,
        out: "y",
        shape: Shape::Matrix {
            rows: Len::V,
            cols: Len::Params,
        },
        doc: |s| {
            format!(
                "The joint torque regressor `Y(q, v, a)` ({} × {}): `tau = Y · params` for any\nstandard parameters. Blocks of joints that do not support a body are structural\nzeros, never computed. {}.",
                s.nv,
                10 * s.n,
                s.state()
            )
        },
        build: |g, model, _| matrix_ids(g, &algo::torque_regressor(g, model, algo::standard_columns(g))),
    },
    Algorithm {
        name: "base_regressor",
        args: QVA,
        out: "y",
        shape: Shape::Matrix {
            rows: Len::V,
            cols: Len::Base,
        },
        doc: |s| {
            format!(
                "The base regressor `Y_b(q, v, a)` ({} × {b}): `tau = Y_b · β` with `β = K · params`\n(`Self::base_params`), the {b} identifiable combinations listed in\n`Self::BASE_GROUPINGS`. {}.",
                s.nv,
                s.state(),
                b = s.nb
            )
        },
        build: |g, model, bases| {
            let y = algo::torque_regressor(g, model, algo::standard_columns(g));
            columns_ids(g, &y, &bases.standard.independent)
        },
    },
    Algorithm {
        name: "principal_regressor",
        args: QVA,
        out: "y",
        shape: Shape::Matrix {
            rows: Len::V,
            cols: Len::Theta,
        },
        doc: |s| {
            format!(
                "The regressor in the paper's parameters ({} × {}): `tau = Y_θ · theta` with\n`theta = (m, J1, J2, J3)` per body, each body's centre of mass and principal axes\nfixed by the description (`Self::NOMINAL_THETA` for its values). {}.",
                s.nv,
                4 * s.n,
                s.state()
            )
        },
        build: |g, model, _| matrix_ids(g, &algo::torque_regressor(g, model, algo::principal_columns(g, model))),
    },
    Algorithm {
        name: "principal_base_regressor",
        args: QVA,
        out: "y",
        shape: Shape::Matrix {
            rows: Len::V,
            cols: Len::PrincipalBase,
        },
        doc: |s| {
            format!(
                "The base regressor of the principal parameterisation ({} × {}): `tau = Y · β_θ`\nwith `β_θ = K_θ · theta` (`Self::principal_base_params`), groupings in\n`Self::PRINCIPAL_BASE_GROUPINGS`. {}.",
                s.nv,
                s.nbt,
                s.state()
            )
        },
        build: |g, model, bases| {
            let y = algo::torque_regressor(g, model, algo::principal_columns(g, model));
            columns_ids(g, &y, &bases.principal.independent)
        },
    },
    Algorithm {
        name: "joint_wrench_regressor",
        args: QVA,
        out: "y",
        shape: Shape::Matrix {
            rows: Len::WrenchRows,
            cols: Len::Params,
        },
        doc: |s| {
            format!(
                "Every joint's full reaction wrench as a linear function of the parameters\n({} × {}): rows `6(j−1)..6j` are `[force; moment]` of joint `j`, as\n[`Self::joint_wrenches`] gives them, equal to this matrix times `params`. {}.",
                6 * s.n,
                10 * s.n,
                s.state()
            )
        },
        build: |g, model, _| matrix_ids(g, &algo::wrench_regressor(g, model)),
    },
    Algorithm {
        name: "body_regressors",
        args: QVA,
        out: "out",
        shape: Shape::PerBody(Record::BodyRegressor),
        doc: |s| {
            format!(
                "The paper's decoupled model, per body: `A_i` with `[F_i; M_i] = A_i θ_i` in the\nbody's centroidal principal frame, `A_i = blkdiag(a_c − g, B(ω, ω̇))`: the force is\n`m (a_c − g)` and the moment `diag(J) ω̇ + ω × diag(J) ω`, with `a_c` the centre of\nmass's acceleration and `ω, ω̇` in principal axes. {}.",
                s.state()
            )
        },
        build: |g, model, _| {
            algo::body_regressors(g, model)
                .iter()
                .flat_map(|m| m.iter().flatten().map(|x| x.id()))
                .collect()
        },
    },
    Algorithm {
        name: "body_resultants",
        args: QVAP,
        out: "out",
        shape: Shape::PerBody(Record::Wrench),
        doc: |s| {
            format!(
                "Each body's resultant of the joint reaction wrenches, through the incidence\nmatrix and body-joint vectors: `F_i = Σ_a S_ia F_a`, `M_i = Σ_a S_ia (M_a + c_ia × F_a)`;\nforce and moment about the centre of mass, in the centroidal principal frame.\nWith the description's parameters, `body_regressors(q, v, a)[i] · θ_i` equals it.\n{}; {}.",
                s.state(),
                s.params()
            )
        },
        build: |g, model, _| force_ids(&algo::body_resultants(g, model)),
    },
    Algorithm {
        name: "base_params",
        args: &[In::Params],
        out: "beta",
        shape: Shape::Vector(Len::Base),
        doc: |s| {
            format!(
                "The {} base parameters of `params` ({} values): `β = K · params`.",
                s.nb,
                10 * s.n
            )
        },
        build: |g, _, bases| base_params_ids(g, &bases.standard, None),
    },
    Algorithm {
        name: "principal_base_params",
        args: &[In::Theta],
        out: "beta",
        shape: Shape::Vector(Len::PrincipalBase),
        doc: |s| {
            format!(
                "The {} base parameters of `theta` ({} values): `β_θ = K_θ · theta`.",
                s.nbt,
                4 * s.n
            )
        },
        build: |g, _, bases| base_params_ids(g, &bases.principal, None),
    },
    Algorithm {
        name: "base_params_joints",
        args: &[In::Params, In::JointParams],
        out: "beta",
        shape: Shape::Vector(Len::BaseJoints),
        doc: |s| {
            format!(
                "The {} base parameters of the standard and joint parameters together:\n`β_j = K_j · [params; joint_params]` (`Self::BASE_JOINTS_K`), groupings in\n`Self::BASE_JOINTS_GROUPINGS`. {}; {}.",
                s.nbj,
                s.params(),
                s.joint_params()
            )
        },
        build: |g, model, bases| base_params_ids(g, &bases.joints, Some(10 * model.dof())),
    },
];

impl Algorithm {
    /// The inherent function's spec, with its outputs built in `g`.
    fn spec(&self, g: &Graph, model: &Model, bases: &Bases, sizes: &Sizes) -> FnSpec<'static> {
        let (ret, output) = match self.shape {
            Shape::Vector(len) => {
                let l = emit::usize_lit(sizes.of(len));
                (
                    quote!([S; #l]),
                    Output::Return(Box::new(|outs: &[TokenStream]| quote!([#(#outs),*]))),
                )
            }
            Shape::PerBody(record) => {
                let (ty, n) = (record.ty(), emit::usize_lit(sizes.n));
                let assemble = move |outs: &[TokenStream]| {
                    let items = outs.chunks(record.outputs()).map(|c| record.build(c));
                    quote!([#(#items),*])
                };
                (quote!([#ty; #n]), Output::Return(Box::new(assemble)))
            }
            Shape::Matrix { rows, cols } => {
                let (r, c) = (sizes.of(rows), sizes.of(cols));
                let (r_lit, c_lit) = (emit::usize_lit(r), emit::usize_lit(c));
                (quote!([[S; #c_lit]; #r_lit]), emit::matrix_output())
            }
        };
        FnSpec {
            name: self.name,
            public: true,
            doc: (self.doc)(sizes),
            args: self.args.iter().map(|a| a.arg(sizes)).collect(),
            ret,
            output,
            outputs: crate::mimic::build(g, model, &[self.layout(sizes)], |g, model| {
                (self.build)(g, model, bases)
            }),
        }
    }

    /// How its outputs go by velocity coordinate (see [`crate::mimic`]).
    fn layout(&self, sizes: &Sizes) -> Block {
        match self.shape {
            Shape::Vector(Len::V) => Block::Rows { cols: 1 },
            Shape::Vector(len) => Block::Plain(sizes.of(len)),
            Shape::PerBody(record) => Block::Plain(sizes.n * record.outputs()),
            Shape::Matrix {
                rows: Len::V,
                cols: Len::V,
            } => Block::Both,
            Shape::Matrix { rows: Len::V, cols } => Block::Rows { cols: sizes.of(cols) },
            Shape::Matrix { rows, cols } => Block::Plain(sizes.of(rows) * sizes.of(cols)),
        }
    }

    /// The trait method: slices checked and viewed as the arrays of the inherent
    /// function.
    fn trait_method(&self, ty: &syn::Ident, sizes: &Sizes) -> TokenStream {
        let fname = format_ident!("{}", self.name);
        let out = format_ident!("{}", self.out);
        let out_name = self.out;
        let names: Vec<syn::Ident> = self
            .args
            .iter()
            .map(|a| format_ident!("{}", a.arg(sizes).name))
            .collect();
        let labels: Vec<&str> = self.args.iter().map(|a| a.arg(sizes).name).collect();
        let views = quote!(#(as_array(#names, #labels)),*);
        let (elem, body) = match self.shape {
            Shape::Vector(len) => {
                let l = emit::usize_lit(sizes.of(len));
                (
                    quote!(S),
                    quote! {
                        use ::dyngen::__private::{as_array, as_array_mut};
                        *as_array_mut::<S, #l>(#out, #out_name) = <#ty>::#fname(#views);
                    },
                )
            }
            Shape::PerBody(record) => {
                let (t, n) = (record.ty(), emit::usize_lit(sizes.n));
                (
                    t.clone(),
                    quote! {
                        use ::dyngen::__private::{as_array, as_array_mut};
                        *as_array_mut::<#t, #n>(#out, #out_name) = <#ty>::#fname(#views);
                    },
                )
            }
            Shape::Matrix { rows, cols } => {
                let (r, c) = (emit::usize_lit(sizes.of(rows)), emit::usize_lit(sizes.of(cols)));
                (
                    quote!(S),
                    quote! {
                        use ::dyngen::__private::{as_array, as_rows_mut};
                        <#ty>::#fname(#views, as_rows_mut::<S, #c, #r>(#out, #out_name));
                    },
                )
            }
        };
        quote! {
            fn #fname<S: ::dyngen::Scalar>(#(#names: &[S],)* #out: &mut [#elem]) {
                #body
            }
        }
    }
}

/// The inherent function of `algorithm` composed of other generated functions, on a
/// robot of more than `above` velocity coordinates (`None`: emit its own graph):
/// `nonlinear_effects` is `rnea` at zero acceleration, the principal regressor is the
/// standard one times each body's constant `P_i` (`π_i = P_i θ_i`), and the base
/// regressors are the independent columns of the full ones (which is what their graphs
/// compute). On a tree `aba` always has its own graph: without rotor inertias the
/// articulated inertia passed to the parent has zero rows along the joint axes, which
/// the one with them lacks. With joints that follow others (any size) `aba` is
/// composed of `crba` and `nonlinear_effects`, solved densely (`crate::mimic`).
fn composed(algorithm: &Algorithm, model: &Model, sizes: &Sizes, above: usize) -> Option<TokenStream> {
    let followers = crate::mimic::has_followers(model);
    if sizes.nv <= above && !(followers && algorithm.name == "aba") {
        return None;
    }
    let [n_l, nq_l, np_l] = [sizes.nv, sizes.nq, 10 * sizes.n].map(emit::usize_lit);
    let zero = quote!(S::ZERO);
    let columns = |full: &str, cols: usize, index: &str, base: usize| {
        let (full, index) = (format_ident!("{}", full), format_ident!("{}", index));
        let (c_l, b_l) = (emit::usize_lit(cols), emit::usize_lit(base));
        (
            quote!(q: &[S; #nq_l], v: &[S; #n_l], a: &[S; #n_l], out: &mut [[S; #b_l]; #n_l]),
            quote!(),
            quote! {
                let mut y = [[#zero; #c_l]; #n_l];
                Self::#full(q, v, a, &mut y);
                for (row, full) in out.iter_mut().zip(&y) {
                    for (x, &c) in row.iter_mut().zip(&Self::#index) {
                        *x = full[c];
                    }
                }
            },
            format!("the columns `Self::{index}` of [`Self::{full}`]"),
        )
    };
    let (params, ret, body, how) = match algorithm.name {
        "aba" if followers => {
            let ancestors = crate::joints::ancestors(model);
            (
                quote!(q: &[S; #nq_l], v: &[S; #n_l], tau: &[S; #n_l], params: &[S; #np_l]),
                quote!(-> [S; #n_l]),
                quote! {
                    #ancestors
                    let mut m = [[#zero; #n_l]; #n_l];
                    Self::crba(q, params, &mut m);
                    let h = Self::nonlinear_effects(q, v, params);
                    let mut a = *tau;
                    for j in 0..#n_l {
                        a[j] -= h[j];
                    }
                    ::dyngen::__private::tree_ldl_solve(&ANCESTORS, &mut m, &mut a);
                    a
                },
                "`M` of [`Self::crba`] and `h` of [`Self::nonlinear_effects`], solved by a dense `LᵀDL`\nfactorisation (joints follow others: a leader moves bodies off its own path, and\nthe articulated-body recursion does not apply)".to_string(),
            )
        }
        "nonlinear_effects" => (
            quote!(q: &[S; #nq_l], v: &[S; #n_l], params: &[S; #np_l]),
            quote!(-> [S; #n_l]),
            quote!(Self::rnea(q, v, &[#zero; #n_l], params)),
            "[`Self::rnea`] at zero acceleration".to_string(),
        ),
        "base_regressor" => columns("joint_torque_regressor", 10 * sizes.n, "BASE_INDEX", sizes.nb),
        "principal_base_regressor" => columns("principal_regressor", 4 * sizes.n, "PRINCIPAL_BASE_INDEX", sizes.nbt),
        "principal_regressor" => {
            let [b_l, t_l] = [sizes.n, 4 * sizes.n].map(emit::usize_lit);
            let frames = dyngen_model::principal_frames(model);
            let maps = frames.iter().map(|f| {
                let rows = f.p_matrix().map(|row| {
                    let row = row.map(emit::f64_lit);
                    quote!([#(#row),*])
                });
                quote!([#(#rows),*])
            });
            (
                quote!(q: &[S; #nq_l], v: &[S; #n_l], a: &[S; #n_l], out: &mut [[S; #t_l]; #n_l]),
                quote!(),
                quote! {
                    /// Each body's `P_i` (10 × 4): its standard parameters are `P_i θ_i`.
                    const PRINCIPAL_MAPS: [[[f64; 4]; 10]; #b_l] = [#(#maps),*];
                    let mut y = [[#zero; #np_l]; #n_l];
                    Self::joint_torque_regressor(q, v, a, &mut y);
                    ::dyngen::__private::principal_columns(&y, &PRINCIPAL_MAPS, out);
                },
                "[`Self::joint_torque_regressor`] times each body's constant `P_i` (10 × 4),\n`π_i = P_i θ_i`"
                    .to_string(),
            )
        }
        _ => return None,
    };
    let fname = format_ident!("{}", algorithm.name);
    let why = if sizes.nv > above {
        format!("Composed (a robot of more than {above} velocity coordinates)")
    } else {
        "Composed".to_string()
    };
    let doc = doc_attrs(&format!("{}\n\n{why}: {how}.", (algorithm.doc)(sizes)));
    Some(quote! {
        #doc
        #[inline]
        pub fn #fname<S: ::dyngen::Scalar>(#params) #ret {
            #body
        }
    })
}

/// Generates the robot type `name` for `model`, with the base parameters `bases`
/// found by [`crate::base::analyse_model`] for the same model. `name` must be a Rust
/// identifier (see [`is_type_name`]).
pub fn generate(model: &Model, name: &str, bases: &Bases, options: &Options) -> GeneratedCode {
    let sizes = Sizes {
        n: model.dof(),
        nq: model.nq(),
        nv: model.nv(),
        nb: bases.standard.count(),
        nbt: bases.principal.count(),
        nbj: bases.joints.count(),
    };
    let ty = format_ident!("{}", name);
    let home = emit::home(&ty);
    let mut selected = options.functions.closure();
    if crate::mimic::has_followers(model) && selected.contains(Capability::ForwardDynamics) {
        // Forward dynamics then solves `M a = τ − h` (see `composed`).
        selected.insert(Capability::MassMatrix);
        selected.insert(Capability::InverseDynamics);
    }
    let mut functions = Vec::new();
    let mut items = Vec::new();
    let mut bodies = Vec::new();
    // The capability traits' methods, by trait.
    let mut methods: Vec<(Capability, TokenStream)> = Vec::new();
    for algorithm in ALGORITHMS.iter().filter(|a| selected.contains(a.capability())) {
        methods.push((algorithm.capability(), algorithm.trait_method(&ty, &sizes)));
        if let Some(item) = composed(algorithm, model, &sizes, options.compose_above_nv) {
            items.push((algorithm.name.to_string(), item));
            continue;
        }
        let g = Graph::new();
        let spec = algorithm.spec(&g, model, bases, &sizes);
        let (emitted, report) = emit::emit_fn(&g, &spec, algorithm.max_statements(options), &home);
        items.push((report.name.clone(), emitted.method));
        bodies.push((report.name.clone(), emitted.body));
        functions.push(report);
    }
    if selected.contains(Capability::JointDynamics) {
        let joints = crate::joints::generate(
            model,
            bases,
            &sizes,
            options.max_statements,
            options.compose_above_nv,
            &home,
        );
        functions.extend(joints.reports);
        items.extend(joints.items);
        bodies.extend(joints.bodies);
        methods.extend(joints.methods.into_iter().map(|m| (Capability::JointDynamics, m)));
    }
    if selected.contains(Capability::Derivatives) {
        let derivatives = derivative_items(model, &sizes, options, &home);
        functions.extend(derivatives.reports);
        items.extend(derivatives.items);
        bodies.extend(derivatives.bodies);
        methods.push((Capability::Derivatives, derivative_methods(sizes.nv)));
    }
    let mut tail = TokenStream::new();
    if selected.contains(Capability::Frames) {
        // With the centroidal functions (`Capability::needs`).
        let frames = crate::frames::generate(model, &ty, &sizes, options);
        functions.extend(frames.reports);
        items.extend(frames.items);
        bodies.extend(frames.bodies);
        methods.push((Capability::Frames, frames.methods));
        methods.push((Capability::Centroidal, frames.centroidal_methods));
        tail = frames.enum_item;
    }
    let head = robot_type(model, &ty, bases, &functions, &items, &methods);
    let mut tokens = head.clone();
    tokens.extend(home_module(&home, bodies.iter().map(|(_, t)| t)));
    tokens.extend(tail.clone());
    GeneratedCode {
        tokens,
        functions,
        items,
        bodies,
        head,
        tail,
        home,
    }
}

/// The functions of [`derivative_items`].
struct DerivativeFns {
    /// Associated functions, by name.
    items: Vec<(String, TokenStream)>,
    /// The bodies of the generated ones ([`emit::Emitted`]), by name.
    bodies: Vec<(String, TokenStream)>,
    reports: Vec<FnReport>,
}

/// By default, robots with more velocity coordinates than this get functions composed
/// of other generated functions wherever a graph of their own would repeat another
/// one's code ([`Options::compose_above_nv`], `Config::compose_above`):
/// `nonlinear_effects`, the principal and base regressors (see `composed`), `aba_joints` (see
/// `crate::joints`), `aba_derivatives` and `aba_joints_derivatives`, `frame_placement`,
/// `frame_jacobian`, `frame_jacobian_time_variation` and `frame_motion` (see
/// `crate::frames`). On large trees
/// what they save in build time matters more than the speed they give up.
///
/// `aba_derivatives`, measured on the 37-coordinate floating humanoid (release, 2
/// cores) before the other functions were composed: its own graph adds 37k lines, and
/// the crate with every function rebuilt in 44.5–45.9 s against 35.7–36.0 s composed
/// (peak 1.43 against 1.25 GB); the
/// composition ran 24.9 µs against 22.2 µs. On the arms the graph is twice as fast
/// (Panda 0.82 against 1.59 µs) and small.
pub const DEFAULT_COMPOSE_ABOVE_NV: usize = 24;

/// The statement budget of a part of the derivative functions (see [`derivative_items`]).
const DERIVATIVE_MAX_STATEMENTS: usize = 800;

/// The derivatives of the dynamics (`crate::derivatives`) as inherent functions
/// writing `dyngen::RneaDerivatives` / `dyngen::AbaDerivatives`, and `M⁻¹` alone.
fn derivative_items(model: &Model, sizes: &Sizes, options: &Options, home: &proc_macro2::Ident) -> DerivativeFns {
    use crate::derivatives;
    let (max_statements, above) = (options.max_statements, options.compose_above_nv);
    // Parts of at most 800 statements: measured on the Panda (release, 2 cores),
    // aba_derivatives ran 967 ns in parts of 1,200 and 811 ns in parts of 800 (400:
    // 772 ns, but the UR5's and rnea_derivatives got slower); rnea_derivatives was
    // unchanged within 2 %. rustc schedules large straight-line functions poorly.
    let max_statements = max_statements.min(DERIVATIVE_MAX_STATEMENTS);
    // Rows and columns go by velocity coordinate.
    let n = sizes.nv;
    let (n_l, nq_l, np_l) = (
        emit::usize_lit(n),
        emit::usize_lit(sizes.nq),
        emit::usize_lit(10 * sizes.n),
    );
    let arg = |id, name, len| Arg { id, name, len };
    let (q, v, a, params) = (
        arg(ARG_Q, "q", sizes.nq),
        arg(ARG_V, "v", n),
        arg(ARG_A, "a", n),
        arg(ARG_PARAMS, "params", 10 * sizes.n),
    );
    // Outputs stored in the fields `fields` of `out`, n × n matrices (`true`) and
    // vectors of n, in order; each field through a flat view of its own name.
    let fields_output = move |fields: &'static [(&'static str, bool)]| {
        let views = fields.iter().map(|&(name, is_matrix)| {
            let f = format_ident!("{}", name);
            if is_matrix {
                quote!(let #f = out.#f.as_flattened_mut();)
            } else {
                quote!(let #f = &mut out.#f;)
            }
        });
        Output::InPlace {
            place: Box::new(move |k: usize| {
                let mut k = k;
                for &(name, is_matrix) in fields {
                    let len = if is_matrix { n * n } else { n };
                    if k < len {
                        let (f, k) = (format_ident!("{}", name), emit::usize_lit(k));
                        return quote!(#f[#k]);
                    }
                    k -= len;
                }
                unreachable!("output {k} beyond the fields")
            }),
            clear: quote!(*out = ::core::default::Default::default();),
            views: quote!(#(#views)*),
        }
    };
    let ids = |m: &[Vec<Expr<'_>>]| m.iter().flatten().map(|x| x.id()).collect::<Vec<_>>();
    let mut items = Vec::new();
    let mut bodies = Vec::new();
    let mut reports = Vec::new();

    let g = Graph::new();
    let outputs = crate::mimic::build(&g, model, &[Block::Both; 3], |g, model| {
        let d = derivatives::rnea_derivatives(g, model);
        let mut outputs = ids(&d.dtau_dq);
        outputs.extend(ids(&d.dtau_dv));
        outputs.extend(ids(&d.m));
        outputs
    });
    let spec = FnSpec {
        name: "rnea_derivatives",
        public: true,
        doc: format!(
            "The derivatives of inverse dynamics `tau = rnea(q, v, a)` (Pinocchio's\n`computeRNEADerivatives`): `∂τ/∂q`, `∂τ/∂v` and `∂τ/∂a = M(q)`, {n} × {n} each, row `i`\nthe derivatives of `tau_i`, written to `out`. Built in closed form (composite\ninertias, momenta and rates of inertia carried up the tree); entries of joints on\ndifferent branches are exact zeros. {}; {}.",
            sizes.state(),
            sizes.params()
        ),
        args: vec![q, v, a, params],
        ret: quote!(::dyngen::RneaDerivatives<S, #n_l>),
        output: fields_output(&[("dtau_dq", true), ("dtau_dv", true), ("dtau_da", true)]),
        outputs,
    };
    let (e, r) = emit::emit_fn(&g, &spec, max_statements, home);
    items.push(("rnea_derivatives".to_string(), e.method));
    bodies.push(("rnea_derivatives".to_string(), e.body));
    reports.push(r);

    // M⁻¹, with each coordinate's rotor inertia `Ia` (joint_params[4 i]) on the
    // diagonal of M: the public `inverse_inertia` passes zeros, the forward-dynamics
    // derivatives with the joint models their armature.
    let nj_l = emit::usize_lit(4 * n);
    let g = Graph::new();
    let crba = crate::mimic::build(&g, model, &[Block::Both], |g, model| {
        algo::crba(g, model).iter().flatten().map(|x| x.id()).collect()
    });
    let mut m: Vec<Vec<Expr<'_>>> = crba
        .chunks(n)
        .map(|row| row.iter().map(|&id| g.expr(id)).collect())
        .collect();
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = row[i] + g.input(algo::ARG_JOINT_PARAMS, (4 * i) as u32);
    }
    let minv = derivatives::inverse_inertia(&g, model, &m);
    let spec = FnSpec {
        name: "__inverse_inertia",
        public: false,
        doc: "`(M(q) + diag(Ia))⁻¹`, `Ia` the rotor inertias in `joint_params`, written to `out`.".to_string(),
        args: vec![
            arg(ARG_Q, "q", sizes.nq),
            arg(ARG_PARAMS, "params", 10 * sizes.n),
            arg(ARG_JOINT_PARAMS, "joint_params", 4 * n),
        ],
        ret: quote!([[S; #n_l]; #n_l]),
        output: emit::matrix_output(),
        outputs: ids(&minv),
    };
    let (inverse, mut r) = emit::emit_fn(&g, &spec, max_statements, home);
    bodies.push(("__inverse_inertia".to_string(), inverse.body));
    let inverse = inverse.method;
    r.name = "inverse_inertia".to_string();
    let inverse_doc = doc_attrs(&format!(
        "`M(q)⁻¹` ({n} × {n}, symmetric; Pinocchio's `computeMinverse`) from the tree's `LᵀDL`\nfactorisation of [`Self::crba`]'s matrix, written to `out`. {}.",
        sizes.params()
    ));
    items.push((
        "inverse_inertia".to_string(),
        quote! {
            #inverse_doc
            #[inline]
            pub fn inverse_inertia<S: ::dyngen::Scalar>(q: &[S; #nq_l], params: &[S; #np_l], out: &mut [[S; #n_l]; #n_l]) {
                Self::__inverse_inertia(q, params, &[S::ZERO; #nj_l], out);
            }
            #inverse
        },
    ));
    reports.push(r);

    // Forward dynamics and its derivatives. `driving` is τ (friction taken off, with
    // the joint models); each path leaves `∂τ/∂q`, `∂τ/∂v` at `a = q̈` in `dq`, `dv`,
    // `slope` adds friction's `∂/∂v` to `dv`, then the products by `−M⁻¹` run as loops.
    // Joints that follow others: `M⁻¹` and forward dynamics are dense (`crate::mimic`).
    let compose = n > above || crate::mimic::has_followers(model);
    let forward = if compose {
        // Composed of the functions above, so a large tree carries one copy of each:
        // `M⁻¹` (with the rotor inertias), `q̈ = M⁻¹ (τ − h)`, rnea derivatives at `q̈`.
        let products = times_minus_minv(model, quote!(&d.dtau_dq), quote!(&d.dtau_dv));
        let n_l = n_l.clone();
        Box::new(move |joint_params: TokenStream, slope: TokenStream| {
            quote! {
                Self::__inverse_inertia(q, params, #joint_params, &mut out.minv);
                let h = Self::nonlinear_effects(q, v, params);
                ::dyngen::__private::accelerations(out, driving, &h);
                let mut d = ::dyngen::RneaDerivatives::<S, #n_l>::default();
                Self::rnea_derivatives(q, v, &out.ddq, params, &mut d);
                let dv = &mut d.dtau_dv;
                #slope
                #products
            }
        }) as Box<dyn Fn(TokenStream, TokenStream) -> TokenStream>
    } else {
        // One generated graph (sharing the kinematics of M⁻¹, h and the rnea at q̈)
        // with the rotor inertias as inputs, for both functions.
        let g = Graph::new();
        let d = derivatives::aba_joints_derivative_parts(&g, model);
        let mut outputs: Vec<NodeId> = d.ddq.iter().map(|x| x.id()).collect();
        outputs.extend(ids(&d.dtau_dq));
        outputs.extend(ids(&d.dtau_dv));
        outputs.extend(ids(&d.minv));
        let spec = FnSpec {
            name: "__aba_derivative_parts",
            public: false,
            doc: "The generated part of [`Self::aba_derivatives`] and [`Self::aba_joints_derivatives`]:\n`ddq`, `(M + diag(Ia))⁻¹`, and `∂τ/∂q`, `∂τ/∂v` at `a = ddq` in the places of `∂q̈/∂q`,\n`∂q̈/∂v`.".to_string(),
            args: vec![
                arg(ARG_Q, "q", sizes.nq),
                arg(ARG_V, "v", n),
                arg(ARG_TAU, "tau", n),
                arg(ARG_PARAMS, "params", 10 * sizes.n),
                arg(ARG_JOINT_PARAMS, "joint_params", 4 * n),
            ],
            ret: quote!(::dyngen::AbaDerivatives<S, #n_l>),
            output: fields_output(&[("ddq", false), ("ddq_dq", true), ("ddq_dv", true), ("minv", true)]),
            outputs,
        };
        let (e, mut r) = emit::emit_fn(&g, &spec, max_statements, home);
        r.name = "aba_derivatives".to_string();
        reports.push(r);
        items.push(("__aba_derivative_parts".to_string(), e.method));
        bodies.push(("__aba_derivative_parts".to_string(), e.body));
        let products = times_minus_minv(model, quote!(&dq), quote!(&*dv));
        Box::new(move |joint_params: TokenStream, slope: TokenStream| {
            quote! {
                Self::__aba_derivative_parts(q, v, driving, params, #joint_params, out);
                let (dq, mut dv) = (out.ddq_dq, out.ddq_dv);
                let dv = &mut dv;
                #slope
                #products
            }
        })
    };
    let zeros = quote!(&[S::ZERO; #nj_l]);
    let plain = forward(zeros, TokenStream::new());
    let aba_doc = doc_attrs(&format!(
        "Forward dynamics and its derivatives (Pinocchio's `computeABADerivatives`):\n`ddq = M⁻¹ (tau − h(q, v))`, `∂q̈/∂q = −M⁻¹ ∂τ/∂q`, `∂q̈/∂v = −M⁻¹ ∂τ/∂v` (at\n`a = ddq`) and `∂q̈/∂τ = M⁻¹`, written to `out`. {}; the products with `M⁻¹` run as\nloops. `AbaDerivatives::semi_implicit_euler` linearises one time step from it.\n`q, v, tau`: {n} positions, velocities, joint torques or forces; {}.",
        if compose {
            "Composed of [`Self::inverse_inertia`], [`Self::nonlinear_effects`] and\n[`Self::rnea_derivatives`] (a large tree, or joints that follow others: one copy of\ntheir code)"
        } else {
            "`M⁻¹` from the tree's `LᵀDL` factorisation (no fill-in;\none division per velocity coordinate), `∂τ/∂q` and `∂τ/∂v` in closed form"
        },
        sizes.params()
    ));
    items.push((
        "aba_derivatives".to_string(),
        quote! {
            #aba_doc
            #[inline]
            pub fn aba_derivatives<S: ::dyngen::Scalar>(
                q: &[S; #nq_l], v: &[S; #n_l], tau: &[S; #n_l], params: &[S; #np_l],
                out: &mut ::dyngen::AbaDerivatives<S, #n_l>,
            ) {
                let driving = tau;
                #plain
            }
        },
    ));

    // With the joint models: the rotor inertias in M, friction taken off τ first and
    // its slope added to ∂τ/∂v before the products.
    let with_slope = forward(
        quote!(joint_params),
        quote! {
            for j in 0..#n_l {
                dv[j][j] += ::dyngen::__private::joint_at(joint_params, j).friction_slope(v[j], coulomb);
            }
        },
    );
    let joints_doc = doc_attrs(&format!(
        "[`Self::aba_derivatives`] of [`Self::aba_joints`], the forward dynamics with the joint\nmodels: `ddq = (M + diag(Ia))⁻¹ (tau − h − Fv·v − Fc·c(v) − F0)`, its derivatives\n`−(M + diag(Ia))⁻¹ ∂τ/∂q` and `−(M + diag(Ia))⁻¹ (∂τ/∂v + diag(Fv + Fc·c′(v)))`, and\n`(M + diag(Ia))⁻¹` in `minv`. With `Coulomb::Sign`, `c′ = 0` (the model is not\ndifferentiable at `v = 0`); `Coulomb::smooth(ε)` gives a smooth linearisation. {}; {}.",
        sizes.params(),
        sizes.joint_params()
    ));
    items.push((
        "aba_joints_derivatives".to_string(),
        quote! {
            #joints_doc
            #[inline]
            pub fn aba_joints_derivatives<S: ::dyngen::Scalar>(
                q: &[S; #nq_l], v: &[S; #n_l], tau: &[S; #n_l], params: &[S; #np_l],
                joint_params: &[S; #nj_l], coulomb: ::dyngen::Coulomb<S>,
                out: &mut ::dyngen::AbaDerivatives<S, #n_l>,
            ) {
                let mut friction_free = *tau;
                for j in 0..#n_l {
                    friction_free[j] -= ::dyngen::__private::joint_at(joint_params, j).friction(v[j], coulomb);
                }
                let driving = &friction_free;
                #with_slope
            }
        },
    ));
    DerivativeFns { items, bodies, reports }
}

/// The products by `−M⁻¹` that finish the forward-dynamics derivatives: over the
/// structurally nonzero rows of each column (coordinates of joints on one path) when
/// the tree has branches, dense loops when every pair of coordinates shares a path.
fn times_minus_minv(model: &Model, dq: TokenStream, dv: TokenStream) -> TokenStream {
    let nv = model.nv();
    let parents = model.coordinate_parents();
    let supports = |a: usize, b: usize| std::iter::successors(Some(b), |&c| parents[c]).any(|c| c == a);
    let on_path = |a: usize, b: usize| supports(a, b) || supports(b, a);
    let support: Vec<Vec<usize>> = (0..nv).map(|c| (0..nv).filter(|&k| on_path(k, c)).collect()).collect();
    if support.iter().all(|rows| rows.len() == nv) {
        return quote!(::dyngen::__private::times_minus_minv(out, #dq, #dv););
    }
    let n_l = emit::usize_lit(nv);
    let columns = support.iter().map(|rows| {
        let rows = rows.iter().map(|&k| emit::usize_lit(k));
        quote!(&[#(#rows),*])
    });
    quote! {
        // Column c of ∂τ/∂q and ∂τ/∂v is zero outside the coordinates of the joints
        // on one path with c's.
        const SUPPORT: [&[usize]; #n_l] = [#(#columns),*];
        ::dyngen::__private::times_minus_minv_sparse(out, #dq, #dv, &SUPPORT);
    }
}

/// The `dyngen::Derivatives` methods of [`derivative_items`].
fn derivative_methods(n: usize) -> TokenStream {
    let n_l = emit::usize_lit(n);
    quote! {
        fn rnea_derivatives<S: ::dyngen::Scalar>(
            q: &[S], v: &[S], a: &[S], params: &[S], dtau_dq: &mut [S], dtau_dv: &mut [S], dtau_da: &mut [S],
        ) {
            use ::dyngen::__private::{as_array, as_rows_mut};
            let mut d = ::dyngen::RneaDerivatives::<S, #n_l>::default();
            Self::rnea_derivatives(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_array(params, "params"), &mut d);
            *as_rows_mut::<S, #n_l, #n_l>(dtau_dq, "dtau_dq") = d.dtau_dq;
            *as_rows_mut::<S, #n_l, #n_l>(dtau_dv, "dtau_dv") = d.dtau_dv;
            *as_rows_mut::<S, #n_l, #n_l>(dtau_da, "dtau_da") = d.dtau_da;
        }
        fn aba_derivatives<S: ::dyngen::Scalar>(
            q: &[S], v: &[S], tau: &[S], params: &[S], ddq: &mut [S], ddq_dq: &mut [S], ddq_dv: &mut [S], minv: &mut [S],
        ) {
            use ::dyngen::__private::{as_array, as_array_mut, as_rows_mut};
            let mut d = ::dyngen::AbaDerivatives::<S, #n_l>::default();
            Self::aba_derivatives(as_array(q, "q"), as_array(v, "v"), as_array(tau, "tau"), as_array(params, "params"), &mut d);
            *as_array_mut::<S, #n_l>(ddq, "ddq") = d.ddq;
            *as_rows_mut::<S, #n_l, #n_l>(ddq_dq, "ddq_dq") = d.ddq_dq;
            *as_rows_mut::<S, #n_l, #n_l>(ddq_dv, "ddq_dv") = d.ddq_dv;
            *as_rows_mut::<S, #n_l, #n_l>(minv, "minv") = d.minv;
        }
        fn inverse_inertia<S: ::dyngen::Scalar>(q: &[S], params: &[S], minv: &mut [S]) {
            use ::dyngen::__private::{as_array, as_rows_mut};
            Self::inverse_inertia(as_array(q, "q"), as_array(params, "params"), as_rows_mut::<S, #n_l, #n_l>(minv, "minv"));
        }
    }
}

/// `#[doc]` attributes, one per line of `text`, so that prettyplease prints `///`
/// lines (a multi-line string would come out as a `/** … */` block).
pub(crate) fn doc_attrs(text: &str) -> TokenStream {
    let lines = text
        .lines()
        .map(|l| if l.is_empty() { String::new() } else { format!(" {l}") });
    quote!(#(#[doc = #lines])*)
}

fn f64_array(xs: &[f64]) -> TokenStream {
    let xs = xs.iter().map(|&x| emit::f64_lit(x));
    quote!([#(#xs),*])
}

fn mat3(m: &[[f64; 3]; 3]) -> TokenStream {
    let rows = m.iter().map(|r| f64_array(r));
    quote!([#(#rows),*])
}

/// The checked model as a `::dyngen::RobotModel` expression, in the generator's
/// numbering: `joints[j - 1]` and `bodies[j - 1]` are joint and body `j`.
fn model_expr(model: &Model) -> TokenStream {
    let joints = model.joints.iter().map(|j| {
        let name = &j.name;
        let kind = match j.kind {
            dyngen_model::JointKind::Revolute => quote!(Revolute),
            dyngen_model::JointKind::Continuous => quote!(Continuous),
            dyngen_model::JointKind::Prismatic => quote!(Prismatic),
            dyngen_model::JointKind::Spherical => quote!(Spherical),
            dyngen_model::JointKind::FreeFlyer => quote!(FreeFlyer),
            dyngen_model::JointKind::Planar => quote!(Planar),
        };
        let parent = emit::usize_lit(j.parent);
        let rotation = mat3(&j.origin.rotation);
        let translation = f64_array(&j.origin.translation);
        let axis = f64_array(&j.axis);
        let limits = match &j.limits {
            Some(l) => {
                let [lower, upper, velocity, effort] = [l.lower, l.upper, l.velocity, l.effort].map(emit::f64_lit);
                quote!(::core::option::Option::Some(::dyngen::JointLimits { lower: #lower, upper: #upper, velocity: #velocity, effort: #effort }))
            }
            None => quote!(::core::option::Option::None),
        };
        let armature = emit::f64_lit(j.dynamics.armature);
        let damping = emit::f64_lit(j.dynamics.damping);
        let friction = emit::f64_lit(j.dynamics.friction);
        let mimic = match j.mimic {
            Some(m) => {
                let leader = emit::usize_lit(m.leader);
                let [multiplier, offset] = [m.multiplier, m.offset].map(emit::f64_lit);
                quote!(::core::option::Option::Some(::dyngen::JointMimic { leader: #leader, multiplier: #multiplier, offset: #offset }))
            }
            None => quote!(::core::option::Option::None),
        };
        quote!(::dyngen::JointModel {
            name: #name,
            kind: ::dyngen::JointType::#kind,
            parent: #parent,
            rotation: #rotation,
            translation: #translation,
            axis: #axis,
            limits: #limits,
            armature: #armature,
            damping: #damping,
            friction: #friction,
            mimic: #mimic,
        })
    });
    let bodies = model.bodies.iter().map(|b| {
        let name = &b.name;
        let mass = emit::f64_lit(b.inertial.mass);
        let com = f64_array(&b.inertial.com);
        let inertia = mat3(&b.inertial.inertia);
        let merged = &b.merged;
        quote!(::dyngen::BodyModel {
            name: #name,
            mass: #mass,
            com: #com,
            inertia: #inertia,
            merged: &[#(#merged),*],
        })
    });
    let frames = model.frames.iter().map(|f| {
        let name = &f.name;
        let body = emit::usize_lit(f.body);
        let rotation = mat3(&f.placement.rotation);
        let translation = f64_array(&f.placement.translation);
        quote!(::dyngen::FrameModel {
            name: #name,
            body: #body,
            rotation: #rotation,
            translation: #translation,
        })
    });
    let (name, base) = (&model.name, &model.base);
    let gravity = f64_array(&model.gravity);
    quote!(::dyngen::RobotModel {
        name: #name,
        gravity: #gravity,
        base: #base,
        joints: &[#(#joints),*],
        bodies: &[#(#bodies),*],
        frames: &[#(#frames),*],
    })
}

/// A row-major matrix that is mostly zeros as a block writing only its non-zero
/// entries, `k[row * cols + col] = x;`, into a zeroed array.
fn sparse_rows(rows: &[Vec<f64>]) -> TokenStream {
    let cols = rows.first().map_or(0, Vec::len);
    let len = emit::usize_lit(rows.len() * cols);
    let cols_lit = emit::usize_lit(cols);
    let entries = rows.iter().enumerate().flat_map(|(r, row)| {
        let cols_lit = cols_lit.clone();
        row.iter().enumerate().filter(|(_, &x)| x != 0.0).map(move |(c, &x)| {
            let (r, c, x) = (emit::usize_lit(r), emit::usize_lit(c), emit::f64_lit(x));
            quote!(k[#r * #cols_lit + #c] = #x;)
        })
    });
    quote!({
        let mut k = [0.0; #len];
        #(#entries)*
        k
    })
}

/// A numbered list of base-parameter formulas, for docs.
fn grouping_list(bp: &BaseParams) -> String {
    bp.groupings
        .iter()
        .enumerate()
        .map(|(k, s)| format!("\n{}. `{s}`", k + 1))
        .collect()
}

/// The type, its constants, its functions, its `RobotDescription` impl and one impl per capability trait.
fn robot_type(
    model: &Model,
    ty: &syn::Ident,
    bases: &Bases,
    functions: &[FnReport],
    items: &[(String, TokenStream)],
    methods: &[(Capability, TokenStream)],
) -> TokenStream {
    let (base, pbase) = (&bases.standard, &bases.principal);
    let n = model.dof();
    let (n_lit, np_lit, nt_lit) = (emit::usize_lit(n), emit::usize_lit(10 * n), emit::usize_lit(4 * n));
    let (nq_lit, nv_lit) = (emit::usize_lit(model.nq()), emit::usize_lit(model.nv()));
    let joint_names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    let body_names: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    let parents: Vec<usize> = model.joints.iter().map(|j| j.parent).collect();
    let parent_lits = parents.iter().map(|&p| emit::usize_lit(p));
    let nominal = f64_array(&model.standard_params());
    let theta = f64_array(&dyngen_model::principal_params(model));
    let gravity = f64_array(&model.gravity);
    let robot_model = model_expr(model);
    let op_counts = functions.iter().map(|f| {
        let name = &f.name;
        let [muls, divs, adds, negs, trig, st] =
            [f.ops.muls, f.ops.divs, f.ops.adds, f.ops.negs, f.ops.trig, f.statements].map(emit::usize_lit);
        quote!((#name, ::dyngen::OpCount { muls: #muls, divs: #divs, adds: #adds, negs: #negs, trig: #trig, statements: #st }))
    });
    let nf = emit::usize_lit(functions.len());
    let items = items.iter().map(|(_, t)| t);
    let (nb, nbt) = (base.count(), pbase.count());
    let (nb_lit, nbt_lit) = (emit::usize_lit(nb), emit::usize_lit(nbt));
    let groupings = &base.groupings;
    let pgroupings = &pbase.groupings;
    let base_index = base.independent.iter().map(|&c| emit::usize_lit(c));
    let pbase_index = pbase.independent.iter().map(|&c| emit::usize_lit(c));
    let base_k = sparse_rows(&base.k);
    let pbase_k = sparse_rows(&pbase.k);
    let (nbk, nbtk) = (emit::usize_lit(nb * 10 * n), emit::usize_lit(nbt * 4 * n));
    let base_doc = doc_attrs(&format!(
        "The {nb} base parameters of the standard parameterisation: the rank of the regressor\nstacked over random states, by QR taking the columns in parameter order and setting\naside each column in the span of those before it (relative tolerance {:e}), so\nearlier bodies' parameters absorb later ones':\n{}",
        crate::base::RANK_TOLERANCE,
        grouping_list(base)
    ));
    let pbase_doc = doc_attrs(&format!(
        "The {nbt} base parameters of the principal parameterisation, found the same way:\n{}",
        grouping_list(pbase)
    ));
    let jbase = &bases.joints;
    let nbj = jbase.count();
    let nj = 4 * model.nv();
    let (nbj_lit, nj_lit) = (emit::usize_lit(nbj), emit::usize_lit(nj));
    let jgroupings = &jbase.groupings;
    let jbase_index = jbase.independent.iter().map(|&c| emit::usize_lit(c));
    let jbase_k = sparse_rows(&jbase.k);
    let nbjk = emit::usize_lit(nbj * (10 * n + nj));
    let nominal_joints = f64_array(&dyngen_model::joint_params::nominal_joint_params(model));
    let jbase_doc = doc_attrs(&format!(
        "The {nbj} base parameters of the standard and joint parameters together\n(`[params; joint_params]`, {} columns, Coulomb friction as `sign(v)`), found the same way:\n{}",
        10 * n + nj,
        grouping_list(jbase)
    ));
    let jbase_k_doc = doc_attrs(&format!(
        "`K_j` ({nbj} × {}, row-major): `β_j = K_j · [params; joint_params]`.",
        10 * n + nj
    ));
    let base_k_doc = doc_attrs(&format!("`K` ({nb} × {}, row-major): `β = K · params`.", 10 * n));
    let pbase_k_doc = doc_attrs(&format!("`K_θ` ({nbt} × {}, row-major): `β_θ = K_θ · theta`.", 4 * n));
    let doc = doc_attrs(&format!(
        "Generated dynamics of `{}`: {n} joints ({}), parents {:?} (0 = base `{}`).",
        model.name,
        joint_names.join(", "),
        parents,
        model.base
    ));
    let robot_name = &model.name;
    let impls = Capability::ALL.into_iter().filter_map(|c| {
        let ms: Vec<&TokenStream> = methods.iter().filter(|(m, _)| *m == c).map(|(_, t)| t).collect();
        if ms.is_empty() {
            return None;
        }
        let name = format_ident!("{}", c.trait_name());
        Some(quote! {
            #[automatically_derived]
            #[allow(clippy::all)]
            impl ::dyngen::#name for #ty {
                #(#ms)*
            }
        })
    });
    quote! {
        #doc
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct #ty;

        #[allow(clippy::all, clippy::pedantic, unused_variables, unused_parens, non_snake_case)]
        impl #ty {
            /// Number of position coordinates (a unit quaternion per ball joint and free flyer).
            pub const NQ: usize = #nq_lit;
            /// Number of velocity coordinates (degrees of freedom).
            pub const NV: usize = #nv_lit;
            /// Number of moving bodies.
            pub const NBODIES: usize = #n_lit;
            /// Number of standard inertial parameters (10 per body).
            pub const NPARAMS: usize = #np_lit;
            /// Number of principal parameters (4 per body: `m, J1, J2, J3`).
            pub const NTHETA: usize = #nt_lit;
            /// Number of base parameters of the standard parameterisation.
            pub const NBASE: usize = #nb_lit;
            /// Number of base parameters of the principal parameterisation.
            pub const NBASE_PRINCIPAL: usize = #nbt_lit;
            /// Number of joint parameters (4 per velocity coordinate: `Ia, Fv, Fc, F0`).
            pub const NJOINT_PARAMS: usize = #nj_lit;
            /// Number of base parameters of the standard and joint parameters together.
            pub const NBASE_JOINTS: usize = #nbj_lit;
            /// Joint names, joint 1 first.
            pub const JOINT_NAMES: [&'static str; #n_lit] = [#(#joint_names),*];
            /// Moving body names, body 1 first.
            pub const BODY_NAMES: [&'static str; #n_lit] = [#(#body_names),*];
            /// Parent body of each body (0 = base), body 1 first.
            pub const PARENTS: [usize; #n_lit] = [#(#parent_lits),*];
            /// Gravity in the base frame, m/s².
            pub const GRAVITY: [f64; 3] = #gravity;
            /// The description's standard parameters, 10 per body:
            /// `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, inertia about the body-frame origin.
            pub const NOMINAL_PARAMS: [f64; #np_lit] = #nominal;
            /// The description's principal parameters `theta = (m, J1, J2, J3)`, 4 per body.
            pub const NOMINAL_THETA: [f64; #nt_lit] = #theta;
            /// The description's joint parameters, 4 per velocity coordinate `[Ia, Fv, Fc, F0]`: rotor inertia
            /// from MJCF `armature` (0 from a URDF), viscous and Coulomb friction from URDF `<dynamics damping
            /// friction>` (MJCF `damping frictionloss`), offset 0.
            pub const NOMINAL_JOINT_PARAMS: [f64; #nj_lit] = #nominal_joints;
            #base_doc
            pub const BASE_GROUPINGS: [&'static str; #nb_lit] = [#(#groupings),*];
            /// Which standard parameters the base parameters are built on (`Y_b` = these columns of `Y`).
            pub const BASE_INDEX: [usize; #nb_lit] = [#(#base_index),*];
            #base_k_doc
            pub const BASE_K: [f64; #nbk] = #base_k;
            #pbase_doc
            pub const PRINCIPAL_BASE_GROUPINGS: [&'static str; #nbt_lit] = [#(#pgroupings),*];
            /// Which principal parameters the principal base parameters are built on.
            pub const PRINCIPAL_BASE_INDEX: [usize; #nbt_lit] = [#(#pbase_index),*];
            #pbase_k_doc
            pub const PRINCIPAL_BASE_K: [f64; #nbtk] = #pbase_k;
            #jbase_doc
            pub const BASE_JOINTS_GROUPINGS: [&'static str; #nbj_lit] = [#(#jgroupings),*];
            /// Which columns of `[params; joint_params]` the joint base parameters are built on.
            pub const BASE_JOINTS_INDEX: [usize; #nbj_lit] = [#(#jbase_index),*];
            #jbase_k_doc
            pub const BASE_JOINTS_K: [f64; #nbjk] = #jbase_k;
            /// The checked model the code was generated from (fixed joints merged), in
            /// the generated numbering: joint and body `j` are `joints[j - 1]` and
            /// `bodies[j - 1]`.
            pub const MODEL: ::dyngen::RobotModel = #robot_model;
            /// Operation counts of the generated functions.
            pub const OP_COUNTS: [(&'static str, ::dyngen::OpCount); #nf] = [#(#op_counts),*];

            #(#items)*
        }

        #[automatically_derived]
        #[allow(clippy::all)]
        impl ::dyngen::RobotDescription for #ty {
            const NAME: &'static str = #robot_name;
            const NQ: usize = #nq_lit;
            const NV: usize = #nv_lit;
            const NBODIES: usize = #n_lit;
            const NPARAMS: usize = #np_lit;
            const NTHETA: usize = #nt_lit;
            const NBASE: usize = #nb_lit;
            const NBASE_PRINCIPAL: usize = #nbt_lit;
            const NJOINT_PARAMS: usize = #nj_lit;
            const NBASE_JOINTS: usize = #nbj_lit;
            const MODEL: ::dyngen::RobotModel = <#ty>::MODEL;
            fn joint_names() -> &'static [&'static str] { &Self::JOINT_NAMES }
            fn body_names() -> &'static [&'static str] { &Self::BODY_NAMES }
            fn parents() -> &'static [usize] { &Self::PARENTS }
            fn nominal_params() -> &'static [f64] { &Self::NOMINAL_PARAMS }
            fn nominal_theta() -> &'static [f64] { &Self::NOMINAL_THETA }
            fn base_groupings() -> &'static [&'static str] { &Self::BASE_GROUPINGS }
            fn base_index() -> &'static [usize] { &Self::BASE_INDEX }
            fn base_k() -> &'static [f64] { &Self::BASE_K }
            fn principal_base_groupings() -> &'static [&'static str] { &Self::PRINCIPAL_BASE_GROUPINGS }
            fn principal_base_index() -> &'static [usize] { &Self::PRINCIPAL_BASE_INDEX }
            fn principal_base_k() -> &'static [f64] { &Self::PRINCIPAL_BASE_K }
            fn nominal_joint_params() -> &'static [f64] { &Self::NOMINAL_JOINT_PARAMS }
            fn base_joints_groupings() -> &'static [&'static str] { &Self::BASE_JOINTS_GROUPINGS }
            fn base_joints_index() -> &'static [usize] { &Self::BASE_JOINTS_INDEX }
            fn base_joints_k() -> &'static [f64] { &Self::BASE_JOINTS_K }
            fn gravity() -> [f64; 3] { Self::GRAVITY }
            fn op_counts() -> &'static [(&'static str, ::dyngen::OpCount)] { &Self::OP_COUNTS }
        }

        #(#impls)*
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_algorithm_has_a_capability() {
        for algorithm in ALGORITHMS {
            assert!(Capability::from_name(algorithm.name).is_some(), "{}", algorithm.name);
        }
    }

    /// A selection generates its groups (with what they are built from) and their
    /// traits only: `joint_dynamics` brings `rnea`, `crba` and the regressors it calls.
    #[test]
    fn a_selection_generates_its_groups_only() {
        let model = dyngen_model::parse_urdf(include_str!("../../robots/ur5/ur5.urdf")).unwrap();
        let bases = crate::analyse_model(&model);
        let options = Options {
            functions: Selection::parse("joint_dynamics").unwrap(),
            ..Options::default()
        };
        let g = generate(&model, "Ur5", &bases, &options);
        let text = g.tokens.to_string();
        let wanted = options.functions.closure();
        for c in Capability::ALL {
            let implemented = text.contains(&format!("impl :: dyngen :: {} for Ur5", c.trait_name()));
            assert_eq!(implemented, wanted.contains(c), "{c}");
        }
        for f in &g.functions {
            if let Some(group) = Capability::from_name(&f.name) {
                assert!(wanted.contains(group), "{} generated", f.name);
            }
        }
        assert!(g.functions.iter().any(|f| f.name == "aba_joints"));
        assert!(!text.contains("fn aba <") && !text.contains("fn frame_jacobian <"));
    }

    /// `pretty` formats the robot type, the frame enum and the bodies' module in pieces
    /// on threads of their own: the result is the file formatted whole, byte for byte,
    /// with every function of its own and with every composable one composed.
    #[test]
    fn pieces_formatted_apart_make_the_file_formatted_whole() {
        let model = dyngen_model::parse_urdf(include_str!("../../robots/ur5/ur5.urdf")).unwrap();
        let bases = crate::analyse_model(&model);
        for compose_above_nv in [usize::MAX, 0] {
            let options = Options {
                compose_above_nv,
                ..Options::default()
            };
            let g = generate(&model, "Ur5", &bases, &options);
            let whole = emit::comment_markers(&prettyplease::unparse(&syn::parse2(g.tokens.clone()).unwrap()));
            assert!(g.bodies.len() > 8, "{} bodies: too few to be split", g.bodies.len());
            assert_eq!(g.pretty(), whole);
        }
    }
}
