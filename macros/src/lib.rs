//! The `robot!` macro: parse, expand, and turn every collected error into a compile
//! error at its span. All the work is in `dyngen-codegen`.

use proc_macro::TokenStream;

/// Generates a robot type with unrolled dynamics. See the `dyngen` crate docs for
/// the two forms (inline graph-theoretic description, or `urdf: "path"`).
#[proc_macro]
pub fn robot(input: TokenStream) -> TokenStream {
    dyngen_codegen::expand_robot_macro(input.into())
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}
