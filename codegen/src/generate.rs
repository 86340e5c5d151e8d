//! The middle layer: a checked model in, the robot type's tokens out, no I/O. The
//! macro, `build.rs` and the command line all call [`generate`].

use crate::algo::{self, Force, Inputs, ARG_A, ARG_PARAMS, ARG_Q, ARG_V};
use crate::base::{self, BaseParams};
use crate::emit::{self, Arg, Assemble, FnReport, FnSpec, Output};
use crate::sym::{Expr, Graph, NodeId};
use dyngen_model::Model;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// Options of the generator.
#[derive(Clone, Debug)]
pub struct Options {
    /// Statements per emitted function before it is split into parts.
    pub max_statements: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_statements: emit::DEFAULT_MAX_STATEMENTS,
        }
    }
}

/// The generated robot type and what went into it.
pub struct Generated {
    pub tokens: TokenStream,
    pub functions: Vec<FnReport>,
    /// Each generated function (with its parts) on its own, by name.
    pub items: Vec<(String, TokenStream)>,
    /// Base parameters of the standard parameterisation.
    pub base: BaseParams,
    /// Base parameters of the principal parameterisation `θ = (m, J1, J2, J3)`.
    pub principal_base: BaseParams,
}

impl Generated {
    /// The code formatted with prettyplease, as written to files and snapshots.
    pub fn pretty(&self) -> String {
        match syn::parse2::<syn::File>(self.tokens.clone()) {
            Ok(file) => prettyplease::unparse(&file),
            Err(_) => self.tokens.to_string(),
        }
    }

    /// One function, formatted, inside an `impl` of the robot type.
    pub fn pretty_function(&self, name: &str) -> Option<String> {
        let (_, tokens) = self.items.iter().find(|(n, _)| n == name)?;
        let file = syn::parse2::<syn::File>(quote!(impl Robot { #tokens })).ok()?;
        Some(prettyplease::unparse(&file))
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

/// Names of the standard parameters, `m1, mx1, …, Izz1, m2, …`.
pub fn standard_param_names(n: usize) -> Vec<String> {
    const NAMES: [&str; 10] = ["m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz"];
    (1..=n)
        .flat_map(|i| NAMES.iter().map(move |s| format!("{s}{i}")))
        .collect()
}

/// Names of the principal parameters, `m1, J1_1, J2_1, J3_1, m2, …`.
pub fn principal_param_names(n: usize) -> Vec<String> {
    (1..=n)
        .flat_map(|i| [format!("m{i}"), format!("J1_{i}"), format!("J2_{i}"), format!("J3_{i}")])
        .collect()
}

/// A regressor as output nodes, structural zeros as the constant 0.
fn matrix_ids<'g>(g: &'g Graph, y: &[Vec<Option<Expr<'g>>>]) -> Vec<NodeId> {
    y.iter()
        .flat_map(|row| row.iter().map(|e| e.unwrap_or_else(|| g.zero()).id()))
        .collect()
}

/// Evaluates a symbolic regressor numerically at `(q, v, a)`.
fn eval_matrix(g: &Graph, ids: &[NodeId], cols: usize, q: &[f64], v: &[f64], a: &[f64]) -> Vec<Vec<f64>> {
    let vals = g.eval(ids, |arg, i| {
        let i = i as usize;
        match arg {
            ARG_Q => q[i],
            ARG_V => v[i],
            ARG_A => a[i],
            _ => 0.0,
        }
    });
    vals.chunks(cols).map(<[f64]>::to_vec).collect()
}

/// Base parameters of a regressor with `cols` columns per body, checked by repeating
/// the analysis with a second seed.
fn base_params(model: &Model, names: &[String], g: &Graph, ids: &[NodeId]) -> BaseParams {
    let p = names.len();
    let run = |seed| base::analyse(model, names, seed, |q, v, a| eval_matrix(g, ids, p, q, v, a));
    let mut first = run(base::SEEDS[0]);
    first.confirmed = run(base::SEEDS[1]).independent == first.independent;
    first
}

/// A matrix written entry by entry into `out`, row-major.
fn rows_of(cols: usize) -> Output<'static> {
    Output::InPlace(Box::new(move |k| {
        let (r, c) = (emit::usize_lit(k / cols), emit::usize_lit(k % cols));
        quote!(out[#r][#c])
    }))
}

fn vector() -> Assemble<'static> {
    Box::new(|outs| quote!([#(#outs),*]))
}

fn wrenches_of() -> Assemble<'static> {
    Box::new(|outs| {
        let ws = outs.chunks(6).map(|c| {
            let (f, m) = (&c[..3], &c[3..]);
            quote!(::dyngen::Wrench {
                force: ::dyngen::nalgebra::Vector3::new(#(#f),*),
                torque: ::dyngen::nalgebra::Vector3::new(#(#m),*),
            })
        });
        quote!([#(#ws),*])
    })
}

fn force_ids(forces: &[Force<'_>]) -> Vec<NodeId> {
    forces
        .iter()
        .flat_map(|w| w.f.0.iter().chain(w.n.0.iter()).map(|e| e.id()))
        .collect()
}

/// Collects emitted functions.
struct Emitter {
    max_statements: usize,
    functions: Vec<FnReport>,
    items: Vec<(String, TokenStream)>,
}

impl Emitter {
    fn emit(&mut self, g: &Graph, spec: FnSpec<'_>) {
        let (tokens, report) = emit::emit_fn(g, &spec, self.max_statements);
        self.items.push((report.name.clone(), tokens));
        self.functions.push(report);
    }
}

/// Generates the robot type `name` for `model`. `name` must be a Rust identifier
/// (see [`is_type_name`]).
pub fn generate(model: &Model, name: &str, options: &Options) -> Generated {
    let n = model.dof();
    let np = 10 * n;
    let nt = 4 * n;
    let (n_lit, np_lit, nt_lit) = (emit::usize_lit(n), emit::usize_lit(np), emit::usize_lit(nt));
    let ty = format_ident!("{}", name);
    let arg = |id: u8, name: &'static str| Arg {
        id,
        name,
        len: if id == ARG_PARAMS { np } else { n },
    };
    let qva = || vec![arg(ARG_Q, "q"), arg(ARG_V, "v"), arg(ARG_A, "a")];
    let qvap = || {
        vec![
            arg(ARG_Q, "q"),
            arg(ARG_V, "v"),
            arg(ARG_A, "a"),
            arg(ARG_PARAMS, "params"),
        ]
    };
    let mut e = Emitter {
        max_statements: options.max_statements,
        functions: Vec::new(),
        items: Vec::new(),
    };
    let params_doc =
        format!("`params`: {np} standard parameters, 10 per body (`Self::NOMINAL_PARAMS` for the description's)");
    let state_doc = format!("`q, v, a`: {n} joint positions (rad or m), velocities, accelerations");

    // Inverse dynamics and its special cases.
    for (fname, inputs, doc, args) in [
        (
            "rnea",
            Inputs::Full,
            format!(" Inverse dynamics, `tau = M(q) a + C(q, v) v + g(q)`, by the unrolled Newton–Euler\n recursion. {state_doc};\n {params_doc}. Returns the {n} joint torques (N·m) or forces (N)."),
            qvap(),
        ),
        (
            "nonlinear_effects",
            Inputs::NoAcceleration,
            format!(" Coriolis, centrifugal and gravity terms `h(q, v) = C(q, v) v + g(q)`, equal to\n `rnea(q, v, 0)`. {params_doc}."),
            vec![arg(ARG_Q, "q"), arg(ARG_V, "v"), arg(ARG_PARAMS, "params")],
        ),
        (
            "generalized_gravity",
            Inputs::Static,
            format!(" Gravity torques `g(q)`, equal to `rnea(q, 0, 0)`. {params_doc}."),
            vec![arg(ARG_Q, "q"), arg(ARG_PARAMS, "params")],
        ),
    ] {
        let g = Graph::new();
        let r = algo::rnea(&g, model, inputs);
        let outputs = r.tau.iter().map(|x| x.id()).collect();
        e.emit(&g, FnSpec { name: fname, doc, args, ret: quote!([S; #n_lit]), outputs, output: Output::Return(vector()) });
    }

    {
        let g = Graph::new();
        let poses = algo::forward_kinematics(&g, model);
        let outputs = poses
            .iter()
            .flat_map(|(r, t)| r.0.iter().flatten().chain(t.0.iter()).map(|x| x.id()))
            .collect();
        e.emit(
            &g,
            FnSpec {
                name: "forward_kinematics",
                doc: format!(" Every body's pose in the base frame, body 1 first: `x_base = rotation · x_body +\n translation`. `q`: {n} joint positions."),
                args: vec![arg(ARG_Q, "q")],
                ret: quote!([::dyngen::Pose<S>; #n_lit]),
                outputs,
                output: Output::Return(Box::new(|outs| {
                    let poses = outs.chunks(12).map(|c| {
                        let (r, t) = (&c[..9], &c[9..]);
                        quote!(::dyngen::Pose {
                            rotation: ::dyngen::nalgebra::Matrix3::new(#(#r),*),
                            translation: ::dyngen::nalgebra::Vector3::new(#(#t),*),
                        })
                    });
                    quote!([#(#poses),*])
                })),
            },
        );
    }

    {
        let g = Graph::new();
        let r = algo::rnea(&g, model, Inputs::Full);
        e.emit(
            &g,
            FnSpec {
                name: "joint_wrenches",
                doc: format!(" The reaction wrench each joint applies to its outboard body: for joint `j`, the\n force (N) and the moment (N·m) about the joint-frame origin, in body `j`'s frame\n (Pinocchio's `data.f[j]` after `rnea`). Arguments as for [`Self::rnea`]; returns {n}\n wrenches, joint 1 first."),
                args: qvap(),
                ret: quote!([::dyngen::Wrench<S>; #n_lit]),
                outputs: force_ids(&r.wrenches),
                output: Output::Return(wrenches_of()),
            },
        );
    }

    {
        let g = Graph::new();
        let m = algo::crba(&g, model);
        e.emit(
            &g,
            FnSpec {
                name: "crba",
                doc: format!(" The joint-space inertia matrix `M(q)` ({n} × {n}, symmetric positive definite) by the\n composite-rigid-body algorithm; entries of joints on different branches are not\n computed. {params_doc}."),
                args: vec![arg(ARG_Q, "q"), arg(ARG_PARAMS, "params")],
                ret: quote!([[S; #n_lit]; #n_lit]),
                                outputs: m.iter().flatten().map(|x| x.id()).collect(),
                output: rows_of(n),
            },
        );
    }

    {
        let g = Graph::new();
        let qdd = algo::aba(&g, model);
        e.emit(
            &g,
            FnSpec {
                name: "aba",
                doc: format!(" Forward dynamics, `a = M(q)⁻¹ (tau − h(q, v))`, by the articulated-body algorithm.\n `q, v, tau`: {n} positions, velocities, joint torques or forces; {params_doc}.\n Returns the {n} joint accelerations; `aba(q, v, rnea(q, v, a)) = a`."),
                args: vec![arg(ARG_Q, "q"), arg(ARG_V, "v"), arg(ARG_A, "tau"), arg(ARG_PARAMS, "params")],
                ret: quote!([S; #n_lit]),
                outputs: qdd.iter().map(|x| x.id()).collect(),
                output: Output::Return(vector()),
            },
        );
    }

    // Regressors, and the base parameters found from them.
    let standard_names = standard_param_names(n);
    let principal_names = principal_param_names(n);
    let base;
    let principal_base;
    {
        let g = Graph::new();
        let y = algo::torque_regressor(&g, model, algo::standard_columns(&g));
        let ids = matrix_ids(&g, &y);
        base = base_params(model, &standard_names, &g, &ids);
        e.emit(
            &g,
            FnSpec {
                name: "joint_torque_regressor",
                doc: format!(" The joint torque regressor `Y(q, v, a)` ({n} × {np}): `tau = Y · params` for any\n standard parameters. Blocks of joints that do not support a body are structural\n zeros, never computed. {state_doc}."),
                args: qva(),
                ret: quote!([[S; #np_lit]; #n_lit]),
                                outputs: ids,
                output: rows_of(np),
            },
        );
        let b = base.count();
        let b_lit = emit::usize_lit(b);
        let cols: Vec<Vec<Option<Expr<'_>>>> = y
            .iter()
            .map(|row| base.independent.iter().map(|&c| row[c]).collect())
            .collect();
        e.emit(
            &g,
            FnSpec {
                name: "base_regressor",
                doc: format!(" The base regressor `Y_b(q, v, a)` ({n} × {b}): `tau = Y_b · β` with `β = K · params`\n (`Self::base_params`), the {b} identifiable combinations listed in\n `Self::BASE_GROUPINGS`. {state_doc}."),
                args: qva(),
                ret: quote!([[S; #b_lit]; #n_lit]),
                                outputs: matrix_ids(&g, &cols),
                output: rows_of(b),
            },
        );
    }
    {
        let g = Graph::new();
        let y = algo::torque_regressor(&g, model, algo::principal_columns(&g, model));
        let ids = matrix_ids(&g, &y);
        principal_base = base_params(model, &principal_names, &g, &ids);
        e.emit(
            &g,
            FnSpec {
                name: "principal_regressor",
                doc: format!(" The regressor in the paper's parameters ({n} × {nt}): `tau = Y_θ · theta` with\n `theta = (m, J1, J2, J3)` per body, each body's centre of mass and principal axes\n fixed by the description (`Self::NOMINAL_THETA` for its values). {state_doc}."),
                args: qva(),
                ret: quote!([[S; #nt_lit]; #n_lit]),
                                outputs: ids,
                output: rows_of(nt),
            },
        );
        let b = principal_base.count();
        let b_lit = emit::usize_lit(b);
        let cols: Vec<Vec<Option<Expr<'_>>>> = y
            .iter()
            .map(|row| principal_base.independent.iter().map(|&c| row[c]).collect())
            .collect();
        e.emit(
            &g,
            FnSpec {
                name: "principal_base_regressor",
                doc: format!(" The base regressor of the principal parameterisation ({n} × {b}): `tau = Y · β_θ`\n with `β_θ = K_θ · theta` (`Self::principal_base_params`), groupings in\n `Self::PRINCIPAL_BASE_GROUPINGS`. {state_doc}."),
                args: qva(),
                ret: quote!([[S; #b_lit]; #n_lit]),
                                outputs: matrix_ids(&g, &cols),
                output: rows_of(b),
            },
        );
    }
    {
        let g = Graph::new();
        let y = algo::wrench_regressor(&g, model);
        let n6 = emit::usize_lit(6 * n);
        e.emit(
            &g,
            FnSpec {
                name: "joint_wrench_regressor",
                doc: format!(" Every joint's full reaction wrench as a linear function of the parameters\n ({} × {np}): rows `6(j−1)..6j` are `[force; moment]` of joint `j`, as\n [`Self::joint_wrenches`] gives them, equal to this matrix times `params`. {state_doc}.", 6 * n),
                args: qva(),
                ret: quote!([[S; #np_lit]; #n6]),
                                outputs: matrix_ids(&g, &y),
                output: rows_of(np),
            },
        );
    }
    {
        let g = Graph::new();
        let a = algo::body_regressors(&g, model);
        e.emit(
            &g,
            FnSpec {
                name: "body_regressors",
                doc: format!(" The paper's decoupled model, per body: `A_i` with `[F_i; M_i] = A_i θ_i` in the\n body's centroidal principal frame, `A_i = blkdiag(a_c − g, B(ω, ω̇))` (DESIGN §5).\n {state_doc}."),
                args: qva(),
                ret: quote!([::dyngen::BodyRegressor<S>; #n_lit]),
                outputs: a.iter().flat_map(|m| m.iter().flatten().map(|x| x.id())).collect(),
                output: Output::Return(Box::new(|outs| {
                    let bodies = outs.chunks(24).map(|c| {
                        let (f, m) = (&c[..12], &c[12..]);
                        quote!(::dyngen::BodyRegressor {
                            force: ::dyngen::nalgebra::SMatrix::<S, 3, 4>::new(#(#f),*),
                            moment: ::dyngen::nalgebra::SMatrix::<S, 3, 4>::new(#(#m),*),
                        })
                    });
                    quote!([#(#bodies),*])
                })),
            },
        );
    }
    {
        let g = Graph::new();
        let r = algo::body_resultants(&g, model);
        e.emit(
            &g,
            FnSpec {
                name: "body_resultants",
                doc: format!(" Each body's resultant of the joint reaction wrenches, through the incidence\n matrix and body-joint vectors: `F_i = Σ_a S_ia F_a`, `M_i = Σ_a S_ia (M_a + c_ia × F_a)`;\n force and moment about the centre of mass, in the centroidal principal frame.\n With the description's parameters, `body_regressors(q, v, a)[i] · θ_i` equals it.\n {state_doc}; {params_doc}."),
                args: qvap(),
                ret: quote!([::dyngen::Wrench<S>; #n_lit]),
                outputs: force_ids(&r),
                output: Output::Return(wrenches_of()),
            },
        );
    }
    // β = K π and β_θ = K_θ θ as straight-line code.
    for (fname, bp, cols, argname) in [
        ("base_params", &base, np, "params"),
        ("principal_base_params", &principal_base, nt, "theta"),
    ] {
        let g = Graph::new();
        let outs: Vec<NodeId> =
            bp.k.iter()
                .map(|row| {
                    row.iter()
                        .enumerate()
                        .filter(|(_, &x)| x != 0.0)
                        .fold(g.zero(), |acc, (c, &x)| {
                            acc + g.constant(x) * g.input(ARG_PARAMS, c as u32)
                        })
                        .id()
                })
                .collect();
        let b_lit = emit::usize_lit(bp.count());
        e.emit(
            &g,
            FnSpec {
                name: fname,
                doc: format!(
                    " The {} base parameters of `{argname}` ({cols} values): `β = K · {argname}`.",
                    bp.count()
                ),
                args: vec![Arg {
                    id: ARG_PARAMS,
                    name: argname,
                    len: cols,
                }],
                ret: quote!([S; #b_lit]),
                outputs: outs,
                output: Output::Return(vector()),
            },
        );
    }

    let tokens = robot_type(model, &ty, &e, &base, &principal_base);
    Generated {
        tokens,
        functions: e.functions,
        items: e.items,
        base,
        principal_base,
    }
}

/// The type, its constants, its functions and its `Robot` impl.
fn robot_type(model: &Model, ty: &syn::Ident, e: &Emitter, base: &BaseParams, pbase: &BaseParams) -> TokenStream {
    let n = model.dof();
    let (n_lit, np_lit, nt_lit) = (emit::usize_lit(n), emit::usize_lit(10 * n), emit::usize_lit(4 * n));
    let joint_names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    let body_names: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    let parents: Vec<usize> = model.joints.iter().map(|j| j.parent).collect();
    let parent_lits = parents.iter().map(|&p| emit::usize_lit(p));
    let nominal = model.standard_params().into_iter().map(emit::f64_lit);
    let theta = dyngen_model::principal_params(model).into_iter().map(emit::f64_lit);
    let gravity = model.gravity.iter().map(|&x| emit::f64_lit(x));
    let urdf = dyngen_model::to_urdf(model);
    let op_counts = e.functions.iter().map(|f| {
        let name = &f.name;
        let [muls, divs, adds, negs, trig, st] =
            [f.ops.muls, f.ops.divs, f.ops.adds, f.ops.negs, f.ops.trig, f.statements].map(emit::usize_lit);
        quote!((#name, ::dyngen::OpCount { muls: #muls, divs: #divs, adds: #adds, negs: #negs, trig: #trig, statements: #st }))
    });
    let nf = emit::usize_lit(e.functions.len());
    let items = e.items.iter().map(|(_, t)| t);
    let (nb, nbt) = (base.count(), pbase.count());
    let n6_lit = emit::usize_lit(6 * n);
    let (nb_lit, nbt_lit) = (emit::usize_lit(nb), emit::usize_lit(nbt));
    let groupings = &base.groupings;
    let pgroupings = &pbase.groupings;
    let base_index = base.independent.iter().map(|&c| emit::usize_lit(c));
    let pbase_index = pbase.independent.iter().map(|&c| emit::usize_lit(c));
    let base_k = base.k.iter().flatten().map(|&x| emit::f64_lit(x));
    let pbase_k = pbase.k.iter().flatten().map(|&x| emit::f64_lit(x));
    let (nbk, nbtk) = (emit::usize_lit(nb * 10 * n), emit::usize_lit(nbt * 4 * n));
    let group_doc: String = base
        .groupings
        .iter()
        .enumerate()
        .map(|(k, s)| format!("\n {}. `{s}`", k + 1))
        .collect();
    let pgroup_doc: String = pbase
        .groupings
        .iter()
        .enumerate()
        .map(|(k, s)| format!("\n {}. `{s}`", k + 1))
        .collect();
    let base_doc = format!(" The {nb} base parameters of the standard parameterisation (rank of the stacked\n regressor, pivoted QR, relative tolerance {:e}):\n{group_doc}", base::RANK_TOLERANCE);
    let pbase_doc = format!(" The {nbt} base parameters of the principal parameterisation:\n{pgroup_doc}");
    let doc = format!(
        " Generated dynamics of `{}`: {n} joints ({}), parents {:?} (0 = base `{}`).",
        model.name,
        joint_names.join(", "),
        parents,
        model.base
    );
    let robot_name = &model.name;
    quote! {
        #[doc = #doc]
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct #ty;

        #[allow(clippy::all, clippy::pedantic, unused_variables, unused_parens, non_snake_case)]
        impl #ty {
            /// Number of joint positions.
            pub const NQ: usize = #n_lit;
            /// Number of joint velocities.
            pub const NV: usize = #n_lit;
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
            /// Joint names, joint 1 first.
            pub const JOINT_NAMES: [&'static str; #n_lit] = [#(#joint_names),*];
            /// Moving body names, body 1 first.
            pub const BODY_NAMES: [&'static str; #n_lit] = [#(#body_names),*];
            /// Parent body of each body (0 = base), body 1 first.
            pub const PARENTS: [usize; #n_lit] = [#(#parent_lits),*];
            /// Gravity in the base frame, m/s².
            pub const GRAVITY: [f64; 3] = [#(#gravity),*];
            /// The description's standard parameters, 10 per body:
            /// `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, inertia about the body-frame origin.
            pub const NOMINAL_PARAMS: [f64; #np_lit] = [#(#nominal),*];
            /// The description's principal parameters `theta = (m, J1, J2, J3)`, 4 per body.
            pub const NOMINAL_THETA: [f64; #nt_lit] = [#(#theta),*];
            #[doc = #base_doc]
            pub const BASE_GROUPINGS: [&'static str; #nb_lit] = [#(#groupings),*];
            /// Which standard parameters the base parameters are built on (`Y_b` = these columns of `Y`).
            pub const BASE_INDEX: [usize; #nb_lit] = [#(#base_index),*];
            /// `K` ({NBASE} × {NPARAMS}, row-major): `β = K · params`.
            pub const BASE_K: [f64; #nbk] = [#(#base_k),*];
            #[doc = #pbase_doc]
            pub const PRINCIPAL_BASE_GROUPINGS: [&'static str; #nbt_lit] = [#(#pgroupings),*];
            /// Which principal parameters the principal base parameters are built on.
            pub const PRINCIPAL_BASE_INDEX: [usize; #nbt_lit] = [#(#pbase_index),*];
            /// `K_θ` (row-major): `β_θ = K_θ · theta`.
            pub const PRINCIPAL_BASE_K: [f64; #nbtk] = [#(#pbase_k),*];
            /// The model as URDF (fixed joints merged).
            pub const URDF: &'static str = #urdf;
            /// Operation counts of the generated functions.
            pub const OP_COUNTS: [(&'static str, ::dyngen::OpCount); #nf] = [#(#op_counts),*];

            #(#items)*
        }

        #[automatically_derived]
        #[allow(clippy::all)]
        impl ::dyngen::Robot for #ty {
            const NAME: &'static str = #robot_name;
            const NQ: usize = #n_lit;
            const NV: usize = #n_lit;
            const NBODIES: usize = #n_lit;
            const NPARAMS: usize = #np_lit;
            const NTHETA: usize = #nt_lit;
            const NBASE: usize = #nb_lit;
            const NBASE_PRINCIPAL: usize = #nbt_lit;
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
            fn urdf() -> &'static str { Self::URDF }
            fn gravity() -> [f64; 3] { Self::GRAVITY }
            fn op_counts() -> &'static [(&'static str, ::dyngen::OpCount)] { &Self::OP_COUNTS }

            fn rnea<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], tau: &mut [S]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<S, #n_lit>(tau, "tau") = <#ty>::rnea(
                    as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_array(params, "params"),
                );
            }
            fn nonlinear_effects<S: ::dyngen::Scalar>(q: &[S], v: &[S], params: &[S], tau: &mut [S]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<S, #n_lit>(tau, "tau") =
                    <#ty>::nonlinear_effects(as_array(q, "q"), as_array(v, "v"), as_array(params, "params"));
            }
            fn generalized_gravity<S: ::dyngen::Scalar>(q: &[S], params: &[S], tau: &mut [S]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<S, #n_lit>(tau, "tau") = <#ty>::generalized_gravity(as_array(q, "q"), as_array(params, "params"));
            }
            fn aba<S: ::dyngen::Scalar>(q: &[S], v: &[S], tau: &[S], params: &[S], a: &mut [S]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<S, #n_lit>(a, "a") = <#ty>::aba(
                    as_array(q, "q"), as_array(v, "v"), as_array(tau, "tau"), as_array(params, "params"),
                );
            }
            fn crba<S: ::dyngen::Scalar>(q: &[S], params: &[S], m: &mut [S]) {
                use ::dyngen::__private::{as_array, as_rows_mut};
                <#ty>::crba(as_array(q, "q"), as_array(params, "params"), as_rows_mut::<S, #n_lit, #n_lit>(m, "m"));
            }
            fn forward_kinematics<S: ::dyngen::Scalar>(q: &[S], poses: &mut [::dyngen::Pose<S>]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<::dyngen::Pose<S>, #n_lit>(poses, "poses") = <#ty>::forward_kinematics(as_array(q, "q"));
            }
            fn joint_wrenches<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], wrenches: &mut [::dyngen::Wrench<S>]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<::dyngen::Wrench<S>, #n_lit>(wrenches, "wrenches") = <#ty>::joint_wrenches(
                    as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_array(params, "params"),
                );
            }
            fn joint_torque_regressor<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]) {
                use ::dyngen::__private::{as_array, as_rows_mut};
                <#ty>::joint_torque_regressor(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_rows_mut::<S, #np_lit, #n_lit>(y, "y"));
            }
            fn joint_wrench_regressor<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]) {
                use ::dyngen::__private::{as_array, as_rows_mut};
                <#ty>::joint_wrench_regressor(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_rows_mut::<S, #np_lit, #n6_lit>(y, "y"));
            }
            fn principal_regressor<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]) {
                use ::dyngen::__private::{as_array, as_rows_mut};
                <#ty>::principal_regressor(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_rows_mut::<S, #nt_lit, #n_lit>(y, "y"));
            }
            fn base_regressor<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]) {
                use ::dyngen::__private::{as_array, as_rows_mut};
                <#ty>::base_regressor(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_rows_mut::<S, #nb_lit, #n_lit>(y, "y"));
            }
            fn principal_base_regressor<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]) {
                use ::dyngen::__private::{as_array, as_rows_mut};
                <#ty>::principal_base_regressor(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_rows_mut::<S, #nbt_lit, #n_lit>(y, "y"));
            }
            fn body_regressors<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], out: &mut [::dyngen::BodyRegressor<S>]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<::dyngen::BodyRegressor<S>, #n_lit>(out, "out") =
                    <#ty>::body_regressors(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"));
            }
            fn body_resultants<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], out: &mut [::dyngen::Wrench<S>]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<::dyngen::Wrench<S>, #n_lit>(out, "out") = <#ty>::body_resultants(
                    as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_array(params, "params"),
                );
            }
            fn base_params<S: ::dyngen::Scalar>(params: &[S], beta: &mut [S]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<S, #nb_lit>(beta, "beta") = <#ty>::base_params(as_array(params, "params"));
            }
            fn principal_base_params<S: ::dyngen::Scalar>(theta: &[S], beta: &mut [S]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<S, #nbt_lit>(beta, "beta") = <#ty>::principal_base_params(as_array(theta, "theta"));
            }
        }
    }
}
