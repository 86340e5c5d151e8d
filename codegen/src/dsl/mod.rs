//! The `robot!` front end (to be written).
use proc_macro2::TokenStream;
pub fn parse(input: TokenStream) -> syn::Result<crate::RobotInput> {
    Err(syn::Error::new_spanned(input, "not yet"))
}
