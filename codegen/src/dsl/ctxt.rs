//! The error context of one `robot!` invocation: every stage records its errors
//! here instead of returning at the first, so the user sees all mistakes in one
//! compile (serde_derive's `Ctxt`).

use proc_macro2::{Punct, Spacing, Span, TokenStream, TokenTree};
use quote::ToTokens;
use std::cell::RefCell;
use std::fmt::Display;

/// Collects errors; must be consumed with [`Ctxt::check`].
#[derive(Default)]
pub struct Ctxt {
    // `None` once checked, so a forgotten check is caught in tests.
    errors: RefCell<Option<Vec<syn::Error>>>,
}

impl Ctxt {
    pub fn new() -> Ctxt {
        Ctxt {
            errors: RefCell::new(Some(Vec::new())),
        }
    }

    /// An error covering the tokens of `obj` (first to last).
    pub fn error_spanned_by<A: ToTokens, T: Display>(&self, obj: A, msg: T) {
        self.syn_error(syn::Error::new_spanned(obj.into_token_stream(), msg));
    }

    pub fn syn_error(&self, err: syn::Error) {
        if let Some(errors) = self.errors.borrow_mut().as_mut() {
            errors.push(err);
        }
    }

    /// All recorded errors, combined into one.
    pub fn check(self) -> syn::Result<()> {
        let errors = self.errors.borrow_mut().take().unwrap_or_default();
        let mut iter = errors.into_iter();
        let Some(mut combined) = iter.next() else {
            return Ok(());
        };
        for rest in iter {
            combined.combine(rest);
        }
        Err(combined)
    }
}

impl Drop for Ctxt {
    fn drop(&mut self) {
        // A programming error in this crate, never a user's: errors would be lost.
        if !std::thread::panicking() && self.errors.borrow().is_some() {
            // ok: a bug of this crate (errors recorded but never reported), not bad input.
            panic!("dyngen DSL: forgot to check for errors");
        }
    }
}

/// A source range, first token to last. `syn::Error::new_spanned` turns such a
/// range into a multi-token underline on stable Rust (where `Span::join` is not
/// available).
#[derive(Copy, Clone, Debug)]
pub struct Loc {
    pub start: Span,
    pub end: Span,
}

impl Loc {
    pub fn at(span: Span) -> Loc {
        Loc { start: span, end: span }
    }

    /// From the start of `self` to the end of `other`.
    pub fn to(self, other: Loc) -> Loc {
        Loc {
            start: self.start,
            end: other.end,
        }
    }

    /// The range of `tokens`, or `fallback` when there are none.
    pub fn of(tokens: &TokenStream, fallback: Span) -> Loc {
        let mut iter = tokens.clone().into_iter();
        match iter.next() {
            None => Loc::at(fallback),
            Some(first) => {
                let start = first.span();
                let end = iter.last().map_or(start, |t| t.span());
                Loc { start, end }
            }
        }
    }
}

impl ToTokens for Loc {
    fn to_tokens(&self, tokens: &mut TokenStream) {
        for span in [self.start, self.end] {
            let mut p = Punct::new('.', Spacing::Alone);
            p.set_span(span);
            tokens.extend([TokenTree::Punct(p)]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_errors_are_combined() {
        let cx = Ctxt::new();
        cx.error_spanned_by(Loc::at(Span::call_site()), "first");
        cx.error_spanned_by(Loc::at(Span::call_site()), "second");
        let err = cx.check().unwrap_err();
        let messages: Vec<String> = err.into_iter().map(|e| e.to_string()).collect();
        assert_eq!(messages, ["first", "second"]);
    }

    #[test]
    fn no_errors_is_ok() {
        assert!(Ctxt::new().check().is_ok());
    }
}
