pub fn expand_robot_macro(_input: proc_macro2::TokenStream) -> syn::Result<proc_macro2::TokenStream> { todo!() }
