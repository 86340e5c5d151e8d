//! The joint models beyond rigid bodies in generated code: rotor inertia and friction,
//! `[Ia, Fv, Fc, F0]` per joint (`dyngen::JointParams`). Each term acts on its own
//! joint only, so the `*_joints` functions are thin additions around the rigid ones
//! (a diagonal, a per-joint torque, four regressor columns per joint); only forward
//! dynamics is generated again, with the rotor inertias in the articulated-body
//! recursion (on large trees composed instead: `M + diag(Ia)` solved by the tree's
//! `LᵀDL` factorisation), and the base parameters come from the rank analysis over all
//! `14n` columns (`Bases::joints`).

use crate::algo::{self, Armature, ARG_JOINT_PARAMS, ARG_PARAMS, ARG_Q, ARG_TAU, ARG_V};
use crate::base::Bases;
use crate::emit::{self, Arg, FnReport, FnSpec, Output};
use crate::generate::Sizes;
use crate::sym::Graph;
use dyngen_model::Model;
use proc_macro2::TokenStream;
use quote::quote;

/// What the joint functions add to the robot type.
pub(crate) struct JointFns {
    /// Inherent functions, by name.
    pub items: Vec<(String, TokenStream)>,
    /// The bodies of the generated functions ([`emit::Emitted`]), by name.
    pub bodies: Vec<(String, TokenStream)>,
    /// The `dyngen::JointDynamics` methods.
    pub methods: Vec<TokenStream>,
    /// The operation count of the generated forward dynamics, reported as `aba_joints`.
    pub reports: Vec<FnReport>,
}

/// `#[doc]` lines.
fn doc(text: &str) -> TokenStream {
    let lines = text
        .lines()
        .map(|l| if l.is_empty() { String::new() } else { format!(" {l}") });
    quote!(#(#[doc = #lines])*)
}

/// The joint functions of the robot type and their `dyngen::JointDynamics` methods. On a robot of more
/// than `compose_above` velocity coordinates `aba_joints` is composed of other
/// functions rather than generated.
/// `const ANCESTORS`: each velocity coordinate's ancestors in
/// [`Model::coordinate_parents`], nearest first, for `dyngen::__private::tree_ldl_solve`.
pub(crate) fn ancestors(model: &Model) -> TokenStream {
    let parents = model.coordinate_parents();
    let ancestors = (0..parents.len()).map(|d| {
        let up = std::iter::successors(parents[d], |&p| parents[p]).map(emit::usize_lit);
        quote!(&[#(#up),*])
    });
    let n_l = emit::usize_lit(parents.len());
    quote!(const ANCESTORS: [&[usize]; #n_l] = [#(#ancestors),*];)
}

pub(crate) fn generate(
    model: &Model,
    bases: &Bases,
    sizes: &Sizes,
    max_statements: usize,
    compose_above: usize,
    home: &proc_macro2::Ident,
) -> JointFns {
    // Joints that follow others: the articulated-body recursion does not apply, and
    // `M + diag(Ia)` is solved densely (`crate::mimic`).
    let followers = crate::mimic::has_followers(model);
    let compose = sizes.nv > compose_above || followers;
    // Rows and joint parameters go by velocity coordinate; parameters by body.
    let n = sizes.nv;
    let (np, nj, nb, nbj) = (10 * sizes.n, 4 * n, sizes.nb, sizes.nbj);
    let [n_l, nq_l, np_l, nj_l, nb_l, nbj_l, nw_l] = [n, sizes.nq, np, nj, nb, nbj, np + nj].map(emit::usize_lit);
    let s = quote!(S);
    let jp = quote!(::dyngen::__private::joint_at(joint_params, j));
    let coulomb_doc = "`coulomb`: `Coulomb::Sign` or `Coulomb::smooth(ε)`";

    // Forward dynamics with the rotor inertias, generated (on large trees composed, see
    // `aba_joints` below); friction is a torque.
    let (aba_armature, bodies, reports) = if compose {
        (quote!(), Vec::new(), Vec::new())
    } else {
        let g = Graph::new();
        let spec = FnSpec {
            name: "aba_armature",
            public: false,
            doc: "Forward dynamics with rotor inertias, `(M + diag(Ia))⁻¹ (tau − h)`: the\ngenerated part of [`Self::aba_joints`]."
                .to_string(),
            args: vec![
                Arg {
                    id: ARG_Q,
                    name: "q",
                    len: sizes.nq,
                },
                Arg {
                    id: ARG_V,
                    name: "v",
                    len: n,
                },
                Arg {
                    id: ARG_TAU,
                    name: "tau",
                    len: n,
                },
                Arg {
                    id: ARG_PARAMS,
                    name: "params",
                    len: np,
                },
                Arg {
                    id: ARG_JOINT_PARAMS,
                    name: "joint_params",
                    len: nj,
                },
            ],
            ret: quote!([S; #n_l]),
            output: Output::Return(Box::new(|outs: &[TokenStream]| quote!([#(#outs),*]))),
            outputs: algo::aba(&g, model, Armature::Input).iter().map(|x| x.id()).collect(),
        };
        let (emitted, mut report) = emit::emit_fn(&g, &spec, max_statements, home);
        report.name = "aba_joints".to_string();
        (
            emitted.method,
            vec![("aba_armature".to_string(), emitted.body)],
            vec![report],
        )
    };

    let rnea_doc = doc(&format!(
        "Inverse dynamics with the joint models: per joint\n`tau_j = rnea_j(q, v, a) + Ia_j·a_j + Fv_j·v_j + Fc_j·c(v_j) + F0_j`, `c` the\nCoulomb model. {}; {};\n{}; {}.",
        sizes.state(),
        sizes.params(),
        sizes.joint_params(),
        coulomb_doc
    ));
    let crba_doc = doc(&format!(
        "`M(q) + diag(Ia)`: the joint-space inertia matrix with the rotor inertias (Pinocchio's\n`crba` with `armature`). {}; {}.",
        sizes.params(),
        sizes.joint_params()
    ));
    let aba_how = if followers {
        "`M + diag(Ia)` of [`Self::crba_joints`] and `h` of\n[`Self::nonlinear_effects`], solved by a dense `LᵀDL` factorisation (joints follow\nothers)".to_string()
    } else if compose {
        format!(
            "`M + diag(Ia)` of [`Self::crba_joints`] and `h` of\n[`Self::nonlinear_effects`], solved by the tree's `LᵀDL` factorisation (no fill-in;\ncomposed, a robot of more than {compose_above} velocity coordinates)"
        )
    } else {
        "the articulated-body\nalgorithm with each rotor inertia added along its joint axis".to_string()
    };
    let aba_doc = doc(&format!(
        "Forward dynamics with the joint models,\n`a = (M(q) + diag(Ia))⁻¹ (tau − h(q, v) − Fv·v − Fc·c(v) − F0)`: {aba_how}, after the\nfriction is taken from `tau`. Inverts [`Self::rnea_joints`]. {}; {}; {}.",
        sizes.params(),
        sizes.joint_params(),
        coulomb_doc
    ));
    let aba_body = if compose {
        let ancestors = ancestors(model);
        quote! {
            #ancestors
            let mut m = [[#s::ZERO; #n_l]; #n_l];
            Self::crba_joints(q, params, joint_params, &mut m);
            let h = Self::nonlinear_effects(q, v, params);
            let mut a = *tau;
            for j in 0..#n_l {
                a[j] -= #jp.friction(v[j], coulomb) + h[j];
            }
            ::dyngen::__private::tree_ldl_solve(&ANCESTORS, &mut m, &mut a);
            a
        }
    } else {
        quote! {
            let mut driving = *tau;
            for j in 0..#n_l {
                driving[j] -= #jp.friction(v[j], coulomb);
            }
            Self::aba_armature(q, v, &driving, params, joint_params)
        }
    };
    let reg_doc = doc(&format!(
        "The joint torque regressor widened with the joint parameters ({n} × {}):\n`tau = Y · [params; joint_params]` equals [`Self::rnea_joints`]. Columns `0..{np}` are\n[`Self::joint_torque_regressor`]; joint `j`'s (1-based) four columns start at\n`{np} + 4(j−1)` and hold `[a_j, v_j, c(v_j), 1]` in row `j`, zero elsewhere. {}; {}.",
        np + nj,
        sizes.state(),
        coulomb_doc
    ));
    let base_reg_doc = doc(&format!(
        "The base regressor of the standard and joint parameters ({n} × {nbj}):\n`tau = Y_bj · β_j` with `β_j = Self::base_params_joints(params, joint_params)`, the\ncolumns `Self::BASE_JOINTS_INDEX` of [`Self::torque_regressor_joints`]. {}; {}.",
        sizes.state(),
        coulomb_doc
    ));

    // The base of the joint analysis keeps the standard base's columns when the QR
    // (columns in order) made the same decisions on them; then the rigid part is
    // `base_regressor` and only the kept joint columns are added.
    let kept = &bases.joints.independent;
    let base_reg_body = if kept.iter().filter(|&&c| c < np).eq(bases.standard.independent.iter()) {
        let joint_cols = kept.iter().enumerate().filter(|(_, &c)| c >= np).map(|(k, &c)| {
            let (k, j, e) = (
                emit::usize_lit(k),
                emit::usize_lit((c - np) / 4),
                emit::usize_lit((c - np) % 4),
            );
            quote!(out[#j][#k] = rows[#j][#e];)
        });
        quote! {
            let mut y = [[#s::ZERO; #nb_l]; #n_l];
            Self::base_regressor(q, v, a, &mut y);
            let rows: [[S; 4]; #n_l] =
                ::core::array::from_fn(|j| ::dyngen::JointParams::regressor_row(v[j], a[j], coulomb));
            for j in 0..#n_l {
                out[j][..#nb_l].copy_from_slice(&y[j]);
                out[j][#nb_l..].fill(#s::ZERO);
            }
            #(#joint_cols)*
        }
    } else {
        quote! {
            let mut y = [[#s::ZERO; #nw_l]; #n_l];
            Self::torque_regressor_joints(q, v, a, coulomb, &mut y);
            for j in 0..#n_l {
                for (k, &c) in Self::BASE_JOINTS_INDEX.iter().enumerate() {
                    out[j][k] = y[j][c];
                }
            }
        }
    };

    let items = vec![
        (
            "rnea_joints".to_string(),
            quote! {
                #rnea_doc
                #[inline]
                pub fn rnea_joints<S: ::dyngen::Scalar>(
                    q: &[S; #nq_l], v: &[S; #n_l], a: &[S; #n_l], params: &[S; #np_l],
                    joint_params: &[S; #nj_l], coulomb: ::dyngen::Coulomb<S>,
                ) -> [S; #n_l] {
                    let mut tau = Self::rnea(q, v, a, params);
                    for j in 0..#n_l {
                        tau[j] += #jp.torque(v[j], a[j], coulomb);
                    }
                    tau
                }
            },
        ),
        (
            "crba_joints".to_string(),
            quote! {
                #crba_doc
                #[inline]
                pub fn crba_joints<S: ::dyngen::Scalar>(
                    q: &[S; #nq_l], params: &[S; #np_l], joint_params: &[S; #nj_l], out: &mut [[S; #n_l]; #n_l],
                ) {
                    Self::crba(q, params, out);
                    for j in 0..#n_l {
                        out[j][j] += joint_params[4 * j];
                    }
                }
            },
        ),
        (
            "aba_joints".to_string(),
            quote! {
                #aba_doc
                #[inline]
                pub fn aba_joints<S: ::dyngen::Scalar>(
                    q: &[S; #nq_l], v: &[S; #n_l], tau: &[S; #n_l], params: &[S; #np_l],
                    joint_params: &[S; #nj_l], coulomb: ::dyngen::Coulomb<S>,
                ) -> [S; #n_l] {
                    #aba_body
                }
                #aba_armature
            },
        ),
        (
            "torque_regressor_joints".to_string(),
            quote! {
                #reg_doc
                #[inline]
                pub fn torque_regressor_joints<S: ::dyngen::Scalar>(
                    q: &[S; #nq_l], v: &[S; #n_l], a: &[S; #n_l], coulomb: ::dyngen::Coulomb<S>,
                    out: &mut [[S; #nw_l]; #n_l],
                ) {
                    let mut y = [[#s::ZERO; #np_l]; #n_l];
                    Self::joint_torque_regressor(q, v, a, &mut y);
                    for j in 0..#n_l {
                        out[j][..#np_l].copy_from_slice(&y[j]);
                        out[j][#np_l..].fill(#s::ZERO);
                        out[j][#np_l + 4 * j..#np_l + 4 * j + 4]
                            .copy_from_slice(&::dyngen::JointParams::regressor_row(v[j], a[j], coulomb));
                    }
                }
            },
        ),
        (
            "base_regressor_joints".to_string(),
            quote! {
                #base_reg_doc
                #[inline]
                pub fn base_regressor_joints<S: ::dyngen::Scalar>(
                    q: &[S; #nq_l], v: &[S; #n_l], a: &[S; #n_l], coulomb: ::dyngen::Coulomb<S>,
                    out: &mut [[S; #nbj_l]; #n_l],
                ) {
                    #base_reg_body
                }
            },
        ),
    ];

    let view = quote!(
        #[allow(unused_imports)]
        use ::dyngen::__private::{as_array, as_array_mut, as_rows_mut};
    );
    let methods = vec![
        quote! {
            fn rnea_joints<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], joint_params: &[S], coulomb: ::dyngen::Coulomb<S>, tau: &mut [S]) {
                #view
                *as_array_mut::<S, #n_l>(tau, "tau") = Self::rnea_joints(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), as_array(params, "params"), as_array(joint_params, "joint_params"), coulomb);
            }
        },
        quote! {
            fn crba_joints<S: ::dyngen::Scalar>(q: &[S], params: &[S], joint_params: &[S], m: &mut [S]) {
                #view
                Self::crba_joints(as_array(q, "q"), as_array(params, "params"), as_array(joint_params, "joint_params"), as_rows_mut::<S, #n_l, #n_l>(m, "m"));
            }
        },
        quote! {
            fn aba_joints<S: ::dyngen::Scalar>(q: &[S], v: &[S], tau: &[S], params: &[S], joint_params: &[S], coulomb: ::dyngen::Coulomb<S>, a: &mut [S]) {
                #view
                *as_array_mut::<S, #n_l>(a, "a") = Self::aba_joints(as_array(q, "q"), as_array(v, "v"), as_array(tau, "tau"), as_array(params, "params"), as_array(joint_params, "joint_params"), coulomb);
            }
        },
        quote! {
            fn torque_regressor_joints<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], coulomb: ::dyngen::Coulomb<S>, y: &mut [S]) {
                #view
                Self::torque_regressor_joints(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), coulomb, as_rows_mut::<S, #nw_l, #n_l>(y, "y"));
            }
        },
        quote! {
            fn base_regressor_joints<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], coulomb: ::dyngen::Coulomb<S>, y: &mut [S]) {
                #view
                Self::base_regressor_joints(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), coulomb, as_rows_mut::<S, #nbj_l, #n_l>(y, "y"));
            }
        },
    ];
    JointFns {
        items,
        bodies,
        methods,
        reports,
    }
}
