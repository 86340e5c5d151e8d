//! Compile-fail tests of the `robot!` macro: every user-facing error of the DSL front
//! end, its message and the token it points at. Regenerate the expected output with
//! `TRYBUILD=overwrite cargo test -p dyngen --test ui` and review every `.stderr`.

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
}
