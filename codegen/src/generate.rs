//! The middle layer: a checked model in, the robot type's tokens out, no I/O. The
//! macro, `build.rs` and the command line all call [`generate`].

use crate::algo::{self, M3, V3};
use crate::emit::{self, Arg, FnReport, FnSpec};
use crate::sym::Graph;
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
                "{:<20} {:>6} mul {:>6} add {:>5} neg {:>3} trig {:>6} statements{}\n",
                f.name,
                f.ops.muls,
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

/// Generates the robot type `name` for `model`. `name` must be a Rust identifier
/// (see [`is_type_name`]).
pub fn generate(model: &Model, name: &str, options: &Options) -> Generated {
    let n = model.dof();
    let np = 10 * n;
    let (n_lit, np_lit) = (emit::usize_lit(n), emit::usize_lit(np));
    let ty = format_ident!("{}", name);
    let max = options.max_statements;
    let state_args = || {
        vec![
            Arg { name: "q", len: n },
            Arg { name: "v", len: n },
            Arg { name: "a", len: n },
            Arg {
                name: "params",
                len: np,
            },
        ]
    };

    let mut functions = Vec::new();
    let mut items = Vec::new();

    // rnea
    {
        let g = Graph::new();
        let r = algo::rnea(&g, model);
        let spec = FnSpec {
            name: "rnea",
            doc: format!(
                " Inverse dynamics, `tau = M(q) a + C(q, v) v + g(q)`, by the unrolled Newton–Euler\n recursion. `q, v, a`: {n} joint positions (rad or m), velocities, accelerations;\n `params`: {np} standard parameters, 10 per body (`Self::NOMINAL_PARAMS` for the\n description's values). Returns the {n} joint torques (N·m) or forces (N)."
            ),
            args: state_args(),
            ret: quote!([S; #n_lit]),
            outputs: r.tau.iter().map(|e| e.id()).collect(),
            assemble: Box::new(|outs| quote!([#(#outs),*])),
        };
        let (tokens, report) = emit::emit_fn(&g, &spec, max);
        items.push((report.name.clone(), tokens));
        functions.push(report);
    }

    // forward kinematics
    {
        let g = Graph::new();
        let poses = algo::forward_kinematics(&g, model);
        let outputs = poses.iter().flat_map(|(r, t)| pose_outputs(r, t)).collect();
        let spec = FnSpec {
            name: "forward_kinematics",
            doc: format!(
                " Every body's pose in the base frame, body 1 first: `x_base = rotation · x_body +\n translation`. `q`: {n} joint positions."
            ),
            args: vec![Arg { name: "q", len: n }],
            ret: quote!([::dyngen::Pose<S>; #n_lit]),
            outputs,
            assemble: Box::new(|outs| {
                let poses = outs.chunks(12).map(|c| {
                    let (r, t) = (&c[..9], &c[9..]);
                    quote!(::dyngen::Pose {
                        rotation: ::dyngen::nalgebra::Matrix3::new(#(#r),*),
                        translation: ::dyngen::nalgebra::Vector3::new(#(#t),*),
                    })
                });
                quote!([#(#poses),*])
            }),
        };
        let (tokens, report) = emit::emit_fn(&g, &spec, max);
        items.push((report.name.clone(), tokens));
        functions.push(report);
    }

    // joint reaction wrenches
    {
        let g = Graph::new();
        let r = algo::rnea(&g, model);
        let outputs = r
            .wrenches
            .iter()
            .flat_map(|(f, m)| f.0.iter().chain(m.0.iter()).map(|e| e.id()))
            .collect();
        let spec = FnSpec {
            name: "joint_wrenches",
            doc: format!(
                " The reaction wrench each joint applies to its outboard body: for joint `j`, the\n force (N) and the moment (N·m) about the joint-frame origin, in body `j`'s frame\n (Pinocchio's `data.f[j]` after `rnea`). Arguments as for [`Self::rnea`]; returns {n}\n wrenches, joint 1 first."
            ),
            args: state_args(),
            ret: quote!([::dyngen::Wrench<S>; #n_lit]),
            outputs,
            assemble: Box::new(|outs| {
                let ws = outs.chunks(6).map(|c| {
                    let (f, m) = (&c[..3], &c[3..]);
                    quote!(::dyngen::Wrench {
                        force: ::dyngen::nalgebra::Vector3::new(#(#f),*),
                        torque: ::dyngen::nalgebra::Vector3::new(#(#m),*),
                    })
                });
                quote!([#(#ws),*])
            }),
        };
        let (tokens, report) = emit::emit_fn(&g, &spec, max);
        items.push((report.name.clone(), tokens));
        functions.push(report);
    }

    let joint_names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    let body_names: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    let parents: Vec<usize> = model.joints.iter().map(|j| j.parent).collect();
    let parent_lits = parents.iter().map(|&p| emit::usize_lit(p));
    let nominal: Vec<TokenStream> = model.standard_params().into_iter().map(emit::f64_lit).collect();
    let gravity: Vec<TokenStream> = model.gravity.iter().map(|&x| emit::f64_lit(x)).collect();
    let urdf = dyngen_model::to_urdf(model);
    let op_counts = functions.iter().map(|f| {
        let name = &f.name;
        let [muls, adds, negs, trig, st] =
            [f.ops.muls, f.ops.adds, f.ops.negs, f.ops.trig, f.statements].map(emit::usize_lit);
        quote!((#name, ::dyngen::OpCount { muls: #muls, adds: #adds, negs: #negs, trig: #trig, statements: #st }))
    });
    let nf = emit::usize_lit(functions.len());
    let item_tokens = items.iter().map(|(_, t)| t);
    let doc = format!(
        " Generated dynamics of `{}`: {n} joints ({}), parents {:?} (0 = base `{}`).",
        model.name,
        joint_names.join(", "),
        parents,
        model.base
    );
    let robot_name = &model.name;

    let tokens = quote! {
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
            /// The model as URDF (fixed joints merged).
            pub const URDF: &'static str = #urdf;
            /// Operation counts of the generated functions.
            pub const OP_COUNTS: [(&'static str, ::dyngen::OpCount); #nf] = [#(#op_counts),*];

            #(#item_tokens)*
        }

        #[automatically_derived]
        impl ::dyngen::Robot for #ty {
            const NAME: &'static str = #robot_name;
            const NQ: usize = #n_lit;
            const NV: usize = #n_lit;
            const NBODIES: usize = #n_lit;
            const NPARAMS: usize = #np_lit;
            fn joint_names() -> &'static [&'static str] { &Self::JOINT_NAMES }
            fn body_names() -> &'static [&'static str] { &Self::BODY_NAMES }
            fn parents() -> &'static [usize] { &Self::PARENTS }
            fn nominal_params() -> &'static [f64] { &Self::NOMINAL_PARAMS }
            fn urdf() -> &'static str { Self::URDF }
            fn gravity() -> [f64; 3] { Self::GRAVITY }
            fn op_counts() -> &'static [(&'static str, ::dyngen::OpCount)] { &Self::OP_COUNTS }
            fn rnea<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], tau: &mut [S]) {
                use ::dyngen::__private::{as_array, as_array_mut};
                *as_array_mut::<S, #n_lit>(tau, "tau") = <#ty>::rnea(
                    as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_array(params, "params"),
                );
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
        }
    };
    Generated {
        tokens,
        functions,
        items,
    }
}

fn pose_outputs(r: &M3<'_>, t: &V3<'_>) -> Vec<u32> {
    r.0.iter().flatten().chain(t.0.iter()).map(|e| e.id()).collect()
}
