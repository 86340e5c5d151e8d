//! Emitters: symbolic outputs in, straight-line Rust out (`quote!`, no strings).
//! A function longer than the statement budget is split into `#[inline(never)]`
//! parts that pass intermediate values through a stack array, because rustc's
//! debug-info pass overflows on functions of a few thousand `let`s.

use crate::sym::{Graph, Node, NodeId, OpCount};
use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};
use std::collections::HashMap;

/// Statements per emitted function before it is split into parts.
pub const DEFAULT_MAX_STATEMENTS: usize = 1200;

/// A function argument: a fixed-size array of scalars, `&[S; len]`, read by the
/// graph's `Input { arg: id }` nodes.
pub struct Arg {
    pub id: u8,
    pub name: &'static str,
    pub len: usize,
}

/// Builds a function's returned value from one expression per output.
pub type Assemble<'a> = Box<dyn Fn(&[TokenStream]) -> TokenStream + 'a>;

/// The place output `k` is stored to, e.g. `out[2][5]`.
pub type Place<'a> = Box<dyn Fn(usize) -> TokenStream + 'a>;

/// How an emitted function hands back its result.
pub enum Output<'a> {
    /// Returned by value, built from all outputs at the end.
    Return(Assemble<'a>),
    /// Written through a final `out: &mut` argument, each output stored right after
    /// the statement that computes it, so large matrices neither tie up registers
    /// until the end nor are copied.
    InPlace(Place<'a>),
}

/// A function to emit: its signature pieces and symbolic outputs.
pub struct FnSpec<'a> {
    pub name: &'a str,
    pub doc: String,
    /// Arguments in signature order.
    pub args: Vec<Arg>,
    /// The return type; or, for [`Output::InPlace`], the type `out` points to.
    pub ret: TokenStream,
    pub output: Output<'a>,
    pub outputs: Vec<NodeId>,
}

/// What was emitted for one function, for reports and docs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FnReport {
    pub name: String,
    pub ops: OpCount,
    pub statements: usize,
    pub parts: usize,
}

/// One `let` (or `let (s, c) = sin_cos`) of the emitted code.
struct Stmt {
    defines: Vec<NodeId>,
    node: Node,
}

/// Emits `spec` as an associated function (plus its parts, if split).
pub fn emit_fn(graph: &Graph, spec: &FnSpec<'_>, max_statements: usize) -> (TokenStream, FnReport) {
    let stmts = schedule(graph, &spec.outputs);
    let ops = OpCount::of(graph, &spec.outputs);
    let fname = format_ident!("{}", spec.name);
    let doc = spec.doc.lines();
    let ret = &spec.ret;
    let in_place = matches!(spec.output, Output::InPlace(_));
    let (out_param, out_arg, ret_ty) = if in_place {
        (Some(quote!(out: &mut #ret)), Some(quote!(out)), quote!())
    } else {
        (None, None, quote!(-> #ret))
    };
    let params: Vec<TokenStream> = spec
        .args
        .iter()
        .map(|a| {
            let n = format_ident!("{}", a.name);
            let len = usize_lit(a.len);
            quote!(#n: &[S; #len])
        })
        .collect();
    let arg_names: Vec<Ident> = spec.args.iter().map(|a| format_ident!("{}", a.name)).collect();
    let op_doc = format!(
        " Generated: {} multiplications, {} divisions, {} additions, {} negations, {} sin/cos; {} statements.",
        ops.muls,
        ops.divs,
        ops.adds,
        ops.negs,
        ops.trig,
        stmts.len()
    );
    let chunks: Vec<&[Stmt]> = if stmts.len() <= max_statements.max(1) {
        vec![&stmts[..]]
    } else {
        stmts.chunks(max_statements.max(1)).collect()
    };
    let report = FnReport {
        name: spec.name.to_string(),
        ops,
        statements: stmts.len(),
        parts: chunks.len(),
    };

    // In place: the output slots of each computed node, and the stores of outputs
    // that are constants or inputs (made up front).
    let mut slots: HashMap<NodeId, Vec<usize>> = HashMap::new();
    let mut early_stores = Vec::new();
    if let Output::InPlace(place) = &spec.output {
        let computed: std::collections::HashSet<NodeId> =
            stmts.iter().flat_map(|s| s.defines.iter().copied()).collect();
        let names = Names {
            spill: &HashMap::new(),
            args: &spec.args,
        };
        for (k, &o) in spec.outputs.iter().enumerate() {
            if computed.contains(&o) {
                slots.entry(o).or_default().push(k);
            } else {
                let (p, x) = (place(k), names.operand(graph, o));
                early_stores.push(quote!(#p = #x;));
            }
        }
    }
    let stores_after = |s: &Stmt| -> TokenStream {
        let Output::InPlace(place) = &spec.output else {
            return TokenStream::new();
        };
        let stores = s.defines.iter().flat_map(|d| {
            let x = var(*d);
            slots.get(d).into_iter().flatten().map(move |&k| {
                let p = place(k);
                quote!(#p = #x;)
            })
        });
        quote!(#(#stores)*)
    };

    if chunks.len() == 1 {
        let names = Names {
            spill: &HashMap::new(),
            args: &spec.args,
        };
        let body = chunks[0].iter().map(|s| {
            let st = emit_stmt(graph, s, &names);
            let stores = stores_after(s);
            quote!(#st #stores)
        });
        let value = match &spec.output {
            Output::Return(assemble) => {
                let outs: Vec<TokenStream> = spec.outputs.iter().map(|&o| names.operand(graph, o)).collect();
                assemble(&outs)
            }
            Output::InPlace(_) => TokenStream::new(),
        };
        let tokens = quote! {
            #(#[doc = #doc])*
            #[doc = ""]
            #[doc = #op_doc]
            #[inline]
            pub fn #fname<S: ::dyngen::Scalar>(#(#params,)* #out_param) #ret_ty {
                #(#early_stores)*
                #(#body)*
                #value
            }
        };
        return (tokens, report);
    }

    // Split: values crossing a part boundary (or returned by value) live in `w`.
    let mut defined_in: HashMap<NodeId, usize> = HashMap::new();
    for (c, chunk) in chunks.iter().enumerate() {
        for s in chunk.iter() {
            for &d in &s.defines {
                defined_in.insert(d, c);
            }
        }
    }
    let mut spill: HashMap<NodeId, usize> = HashMap::new();
    let mark = |id: NodeId, spill: &mut HashMap<NodeId, usize>| {
        let next = spill.len();
        spill.entry(id).or_insert(next);
    };
    for (c, chunk) in chunks.iter().enumerate() {
        for s in chunk.iter() {
            for op in operands(&s.node) {
                if defined_in.get(&op).is_some_and(|&d| d != c) {
                    mark(op, &mut spill);
                }
            }
        }
    }
    if !in_place {
        for &o in &spec.outputs {
            if defined_in.contains_key(&o) {
                mark(o, &mut spill);
            }
        }
    }
    let width = usize_lit(spill.len().max(1));
    let mut parts = Vec::new();
    let mut calls = Vec::new();
    for (c, chunk) in chunks.iter().enumerate() {
        let part = format_ident!("__{}_part{}", spec.name, c);
        let local: HashMap<NodeId, usize> = HashMap::new();
        let names = Names {
            spill: &local,
            args: &spec.args,
        };
        // Loads of values defined in earlier parts.
        let mut loads: Vec<NodeId> = chunk
            .iter()
            .flat_map(|s| operands(&s.node))
            .filter(|op| defined_in.get(op).is_some_and(|&d| d < c))
            .collect();
        loads.sort_unstable();
        loads.dedup();
        let load_stmts = loads.iter().map(|&id| {
            let x = var(id);
            let k = usize_lit(spill[&id]);
            quote!(let #x = w[#k];)
        });
        let body = chunk.iter().map(|s| {
            let st = emit_stmt(graph, s, &names);
            let stores = stores_after(s);
            quote!(#st #stores)
        });
        let spills = chunk.iter().flat_map(|s| s.defines.iter()).filter_map(|id| {
            spill.get(id).map(|&k| {
                let k = usize_lit(k);
                let x = var(*id);
                quote!(w[#k] = #x;)
            })
        });
        parts.push(quote! {
            #[doc(hidden)]
            #[inline(never)]
            #[allow(unused_variables)]
            fn #part<S: ::dyngen::Scalar>(#(#params,)* w: &mut [S; #width], #out_param) {
                #(#load_stmts)*
                #(#body)*
                #(#spills)*
            }
        });
        calls.push(quote!(Self::#part(#(#arg_names,)* &mut w, #out_arg);));
    }
    let value = match &spec.output {
        Output::Return(assemble) => {
            let names = Names {
                spill: &spill,
                args: &spec.args,
            };
            let outs: Vec<TokenStream> = spec
                .outputs
                .iter()
                .map(|&o| match spill.get(&o) {
                    Some(&k) => {
                        let k = usize_lit(k);
                        quote!(w[#k])
                    }
                    None => names.operand(graph, o),
                })
                .collect();
            assemble(&outs)
        }
        Output::InPlace(_) => TokenStream::new(),
    };
    let tokens = quote! {
        #(#[doc = #doc])*
        #[doc = ""]
        #[doc = #op_doc]
        pub fn #fname<S: ::dyngen::Scalar>(#(#params,)* #out_param) #ret_ty {
            let mut w = [<S as ::dyngen::Scalar>::ZERO; #width];
            #(#early_stores)*
            #(#calls)*
            #value
        }
        #(#parts)*
    };
    (tokens, report)
}

fn operands(node: &Node) -> Vec<NodeId> {
    match *node {
        Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) => vec![a, b],
        Node::Neg(a) | Node::Sin(a) | Node::Cos(a) => vec![a],
        Node::Const(_) | Node::Input { .. } => vec![],
    }
}

/// The live computed nodes in evaluation order, with `sin` and `cos` of one angle
/// fused into one `sin_cos` statement placed where the first of the two was.
fn schedule(graph: &Graph, outputs: &[NodeId]) -> Vec<Stmt> {
    let live = graph.live(outputs);
    let mut trig: HashMap<NodeId, (Option<NodeId>, Option<NodeId>)> = HashMap::new();
    for (id, &l) in live.iter().enumerate() {
        match (l, graph.node(id as NodeId)) {
            (true, Node::Sin(a)) => trig.entry(a).or_default().0 = Some(id as NodeId),
            (true, Node::Cos(a)) => trig.entry(a).or_default().1 = Some(id as NodeId),
            _ => {}
        }
    }
    let mut stmts = Vec::new();
    for (id, &l) in live.iter().enumerate() {
        let id = id as NodeId;
        let node = graph.node(id);
        if !l {
            continue;
        }
        match node {
            Node::Const(_) | Node::Input { .. } => {}
            Node::Sin(a) | Node::Cos(a) => match trig[&a] {
                (Some(s), Some(c)) if id == s.min(c) => {
                    stmts.push(Stmt {
                        defines: vec![s, c],
                        node: Node::Sin(a),
                    });
                }
                (Some(_), Some(_)) => {}
                _ => stmts.push(Stmt {
                    defines: vec![id],
                    node,
                }),
            },
            _ => stmts.push(Stmt {
                defines: vec![id],
                node,
            }),
        }
    }
    stmts
}

fn var(id: NodeId) -> Ident {
    format_ident!("x{}", id)
}

struct Names<'a> {
    spill: &'a HashMap<NodeId, usize>,
    args: &'a [Arg],
}

impl Names<'_> {
    fn operand(&self, graph: &Graph, id: NodeId) -> TokenStream {
        match graph.node(id) {
            Node::Const(bits) => constant(f64::from_bits(bits)),
            Node::Input { arg, index } => {
                let name = self
                    .args
                    .iter()
                    .find(|a| a.id == arg)
                    .map_or("missing_argument", |a| a.name);
                let a = format_ident!("{}", name);
                let i = usize_lit(index as usize);
                quote!(#a[#i])
            }
            _ => match self.spill.get(&id) {
                Some(&k) => {
                    let k = usize_lit(k);
                    quote!(w[#k])
                }
                None => {
                    let x = var(id);
                    quote!(#x)
                }
            },
        }
    }
}

/// A constant as the scalar type: `S::from_f64(0.425)`.
pub fn constant(x: f64) -> TokenStream {
    if x == 0.0 {
        return quote!(<S as ::dyngen::Scalar>::ZERO);
    }
    let lit = Literal::f64_unsuffixed(x.abs());
    if x.is_sign_negative() && x != 0.0 {
        quote!(<S as ::dyngen::Scalar>::from_f64(-#lit))
    } else {
        quote!(<S as ::dyngen::Scalar>::from_f64(#lit))
    }
}

fn emit_stmt(graph: &Graph, s: &Stmt, names: &Names<'_>) -> TokenStream {
    let op = |id: NodeId| names.operand(graph, id);
    let x = var(s.defines[0]);
    match s.node {
        Node::Add(a, b) => {
            let (a, b) = (op(a), op(b));
            quote!(let #x = #a + #b;)
        }
        Node::Sub(a, b) => {
            let (a, b) = (op(a), op(b));
            quote!(let #x = #a - #b;)
        }
        Node::Mul(a, b) => {
            let (a, b) = (op(a), op(b));
            quote!(let #x = #a * #b;)
        }
        Node::Div(a, b) => {
            let (a, b) = (op(a), op(b));
            quote!(let #x = #a / #b;)
        }
        Node::Neg(a) => {
            let a = op(a);
            quote!(let #x = -#a;)
        }
        Node::Sin(a) if s.defines.len() == 2 => {
            let c = var(s.defines[1]);
            let a = op(a);
            quote!(let (#x, #c) = ::dyngen::Scalar::sin_cos(#a);)
        }
        Node::Sin(a) => {
            let a = op(a);
            quote!(let #x = ::dyngen::Scalar::sin(#a);)
        }
        Node::Cos(a) => {
            let a = op(a);
            quote!(let #x = ::dyngen::Scalar::cos(#a);)
        }
        Node::Const(_) | Node::Input { .. } => TokenStream::new(),
    }
}

/// A `usize` literal for array lengths in emitted signatures.
pub fn usize_lit(n: usize) -> Literal {
    Literal::usize_unsuffixed(n)
}

/// An `f64` literal for constant tables (no scalar conversion).
pub fn f64_lit(x: f64) -> TokenStream {
    let lit = Literal::f64_unsuffixed(x.abs());
    if x.is_sign_negative() && x != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}
