//! # dyngen-codegen
//!
//! Turns a robot description into specialised, unrolled Rust. One pipeline, three
//! front doors (the `robot!` macro, `build.rs`, the command line):
//! **front end → checked model → base-parameter analysis → symbolic graph → emitted
//! code**. Each front door checks the model, calls [`analyse_model`] and hands both
//! to [`generate`].
//!
//! In `build.rs`:
//! ```no_run
//! dyngen_codegen::compile_urdf("ur5.urdf", "Ur5").unwrap();
//! ```
//! then in the crate `include!(concat!(env!("OUT_DIR"), "/ur5.rs"));` defines `Ur5`.

pub mod algo;
pub mod base;
mod build;
mod capability;
pub mod derivatives;
pub mod dsl;
pub mod emit;
pub mod frames;
mod generate;
mod joints;
mod mimic;
pub mod sym;

pub use base::{analyse_model, analyse_rigid, BaseParams, Bases};
pub use build::{compile_urdf, write_if_changed, Config, Error};
pub use capability::{Capability, Selection, UnknownCapability};
pub use generate::{generate, is_type_name, GeneratedCode, Options, DEFAULT_COMPOSE_ABOVE_NV};

use dyngen_model::Model;
use proc_macro2::TokenStream;
use quote::quote;

/// What a `robot!` invocation asked for.
pub struct RobotInput {
    /// The type name to generate.
    pub name: syn::Ident,
    pub source: RobotSource,
    /// `functions: [..]`, or all.
    pub functions: Selection,
}

pub enum RobotSource {
    /// The inline graph-theoretic description, already checked and turned into a
    /// description (it still goes through `Description::build`).
    Dsl(Box<dyngen_model::Description>),
    /// `urdf: "path"`, relative to `CARGO_MANIFEST_DIR`.
    Urdf(syn::LitStr),
}

/// Why generated code cannot be made for `model`, if it cannot: a free flyer beyond
/// the floating base (a second free body).
pub fn unsupported(model: &Model) -> Option<String> {
    let j = model
        .joints
        .iter()
        .skip(1)
        .find(|j| j.kind == dyngen_model::JointKind::FreeFlyer)?;
    Some(format!(
        "joint `{}` is a second free flyer (a free body beside the floating base); generated code takes one \
         floating base, as joint 1. Load the robot at run time instead (`dyngen_model::load_robot`, then \
         `Model::multibody` and `dyngen_algo`'s algorithms, or `dyngen.load` in Python)",
        j.name
    ))
}

/// The whole `robot!` macro: parse, build the checked model, generate.
pub fn expand_robot_macro(input: TokenStream) -> syn::Result<TokenStream> {
    let input = dsl::parse(input)?;
    let name = input.name.to_string();
    let (model, rebuild_on) = match &input.source {
        RobotSource::Dsl(desc) => {
            let model = desc.build().map_err(|errors| {
                let text = errors.iter().map(|e| e.to_string()).collect::<Vec<_>>().join("\n");
                syn::Error::new(input.name.span(), text)
            })?;
            (model, None)
        }
        RobotSource::Urdf(lit) => {
            let path = manifest_path(&lit.value());
            let model = dyngen_model::load_robot(&path).map_err(|e| syn::Error::new(lit.span(), e.to_string()))?;
            (model, Some(path))
        }
    };
    if let Some(why) = unsupported(&model) {
        let span = match &input.source {
            RobotSource::Urdf(lit) => lit.span(),
            RobotSource::Dsl(_) => input.name.span(),
        };
        return Err(syn::Error::new(span, why));
    }
    let bases = base::analyse_model(&model);
    let options = Options {
        functions: input.functions,
        ..Options::default()
    };
    let generated = generate(&model, &name, &bases, &options);
    let tokens = generated.tokens;
    let span = match &input.source {
        RobotSource::Urdf(lit) => lit.span(),
        RobotSource::Dsl(_) => input.name.span(),
    };
    let warnings = model
        .warnings
        .iter()
        .map(|w| compile_warning(span, &w.warning_message()));
    // Make the crate rebuild when the URDF changes.
    let watch = rebuild_on.map(|p| {
        let p = p.to_string_lossy().into_owned();
        quote!(
            const _: &[u8] = include_bytes!(#p);
        )
    });
    Ok(quote!(#tokens #watch #(#warnings)*))
}

/// A compiler warning at `span` saying `message`, from a procedural macro on stable
/// Rust: the use of a deprecated constant, whose note is the message (rustc prints
/// "use of deprecated constant …: message"). What `build.rs` prints as
/// `cargo:warning`, the macro says so; a crate built with `-D warnings` refuses it.
fn compile_warning(span: proc_macro2::Span, message: &str) -> TokenStream {
    quote::quote_spanned!(span=>
        const _: () = {
            #[deprecated(note = #message)]
            const DYNGEN_WARNING: () = ();
            DYNGEN_WARNING
        };
    )
}

fn manifest_path(path: &str) -> std::path::PathBuf {
    let p = std::path::Path::new(path);
    match std::env::var_os("CARGO_MANIFEST_DIR") {
        Some(dir) if p.is_relative() => std::path::PathBuf::from(dir).join(p),
        _ => p.to_path_buf(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The followers' rules are in the generated `MODEL` (the numbers are checked in
    /// `tests/tests/integration/census.rs`, `generated_mimic_robots_match_pinocchio`).
    #[test]
    fn the_macro_generates_mimic_joints() {
        let input = quote! { name: Gripper, urdf: "../tests/fixtures/mimic/arm_linkage_gripper.urdf" };
        let code = expand_robot_macro(input).unwrap().to_string();
        assert_eq!(code.matches(":: dyngen :: JointMimic {").count(), 5, "five followers");
    }
}
