//! Emitters: symbolic outputs in, straight-line Rust out (`quote!`, no strings).
//! A long body is written in blocks of statements (`grouped`), because rustc's
//! debug-info emitter overflows on a few thousand nested `let` scopes. A body longer
//! than the statement budget is split into `#[inline(never)]` parts that pass
//! intermediate values through a stack array, which bounds the optimiser's work
//! per function at the cost of those loads and stores.

use crate::sym::{Graph, Node, NodeId, OpCount};
use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};
use std::collections::{HashMap, HashSet};

/// Statements per emitted function before it is split into parts.
///
/// 6,000 keeps the humanoid's (31 joints + free flyer) `aba` (5,228 statements),
/// `rnea`, `crba` and centroidal map whole. Measured on it (release, native CPU,
/// one sitting): in parts of 1,200 the values crossing parts took 1,303 stack slots
/// and `aba` ran 2.7–2.9 µs; whole it runs 2.6–2.7 µs, and `rnea` 842 → 739 ns,
/// `centroidal_map` 732 → 661 ns. The regressors and the derivatives keep smaller
/// parts of their own (build time, and measured speed, respectively).
pub const DEFAULT_MAX_STATEMENTS: usize = 6000;

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
    /// until the end nor are copied. `clear` sets all of `out` to zero in one
    /// statement, after which only the outputs that are not structural zeros are
    /// stored. `views` are `let`s, written after `clear` at the top of every body that
    /// stores outputs, that the places may name: a matrix is stored through a flat
    /// view, `m[k]` rather than `out[r][c]`, which halves what rustc type-checks per
    /// store (on the humanoid's joint wrench regressor, 7,600 stores, 1.1 s → 0.4 s).
    InPlace {
        place: Place<'a>,
        clear: TokenStream,
        views: TokenStream,
    },
}

/// A row-major matrix `[[S; cols]; rows]` written through `out`, zeroed first:
/// output `k` is element `k` of `out` flattened.
pub fn matrix_output() -> Output<'static> {
    Output::InPlace {
        place: Box::new(move |k: usize| {
            let k = usize_lit(k);
            quote!(out[#k])
        }),
        clear: quote!(out.as_flattened_mut().fill(S::ZERO);),
        views: quote!(let out = out.as_flattened_mut();),
    }
}

/// A function to emit: its signature pieces and symbolic outputs.
pub struct FnSpec<'a> {
    pub name: &'a str,
    /// `pub fn`, or a private helper of the type's other functions.
    pub public: bool,
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

/// Longest expression, in estimated characters, that a statement takes by writing
/// operands inside it: it keeps each statement on one formatted line.
const MAX_EXPR_CHARS: usize = 64;

/// Which computed nodes are written inside the one expression that uses them rather
/// than as a `let` of their own. Only single-use nodes are, so nothing is computed
/// twice. A product whose one use is a sum or difference is always written inside it,
/// as `Scalar::mul_add` (one per sum): where the target fuses multiply and add, that is
/// one instruction with one rounding, as a C++ compiler contracts `a * b + c`; elsewhere
/// it is the product and the sum, and the values are bit-identical to one `let` per
/// node (Rust itself never contracts).
struct Inlined(HashSet<NodeId>);

impl Inlined {
    fn new(graph: &Graph, stmts: &[Stmt], outputs: &[NodeId]) -> Inlined {
        let mut uses: HashMap<NodeId, usize> = HashMap::new();
        for s in stmts {
            for op in operands(&s.node) {
                *uses.entry(op).or_default() += 1;
            }
        }
        for &o in outputs {
            *uses.entry(o).or_default() += 2;
        }
        let mut chars: HashMap<NodeId, usize> = HashMap::new();
        let mut inlined = HashSet::new();
        let atom = |id: NodeId| match graph.node(id) {
            Node::Const(_) => 45,
            Node::Input { .. } => 10,
            _ => 6,
        };
        for s in stmts {
            if s.defines.len() != 1 || matches!(s.node, Node::Sin(_) | Node::Cos(_)) {
                continue;
            }
            let mut len = 3 * operands(&s.node).len();
            let mut fusable = matches!(s.node, Node::Add(..) | Node::Sub(..));
            // The right operand first: `fused` prefers it.
            for op in operands(&s.node).into_iter().rev() {
                let own = atom(op);
                let single = uses.get(&op) == Some(&1);
                match chars.get(&op) {
                    Some(&inner) if single && fusable && matches!(graph.node(op), Node::Mul(..)) => {
                        fusable = false;
                        inlined.insert(op);
                        len += inner + 2;
                    }
                    Some(&inner) if single && len + inner + 2 <= MAX_EXPR_CHARS => {
                        inlined.insert(op);
                        len += inner + 2;
                    }
                    _ => len += own,
                }
            }
            chars.insert(s.defines[0], len);
        }
        Inlined(inlined)
    }

    fn contains(&self, id: NodeId) -> bool {
        self.0.contains(&id)
    }

    /// The operands `id`'s statement reads from other statements, inputs and
    /// constants, through the nodes written inside it.
    fn leaves(&self, graph: &Graph, node: &Node, out: &mut Vec<NodeId>) {
        for op in operands(node) {
            if self.contains(op) {
                self.leaves(graph, &graph.node(op), out);
            } else {
                out.push(op);
            }
        }
    }
}

/// An emitted function: a thin associated function of the robot type, and its body,
/// a free function in the module `home::name` (with its parts, if split).
///
/// The bodies live outside the robot type's `impl` because rustc assigns a method to
/// the codegen unit of its self type: in the `impl`, every generated function would
/// go to one unit and LLVM would optimise them all on one core. As free functions in
/// their own modules they spread over the codegen units and build in parallel.
pub struct Emitted {
    /// The associated function, for the type's `impl`.
    pub method: TokenStream,
    /// The module holding the body, for the robot's [`home`] module.
    pub body: TokenStream,
}

/// The module (beside the robot type `ty`) that holds the bodies of its generated
/// functions, one submodule each.
pub fn home(ty: &Ident) -> Ident {
    format_ident!("__{}_generated", ty)
}

/// Emits `spec` as an associated function whose body lives in the module
/// `home::name` (see [`Emitted`]).
pub fn emit_fn(graph: &Graph, spec: &FnSpec<'_>, max_statements: usize, home: &Ident) -> (Emitted, FnReport) {
    let scheduled = schedule(graph, &spec.outputs);
    let inlined = Inlined::new(graph, &scheduled, &spec.outputs);
    let stmts: Vec<Stmt> = scheduled
        .into_iter()
        .filter(|s| !(s.defines.len() == 1 && inlined.contains(s.defines[0])))
        .collect();
    let ops = OpCount::of(graph, &spec.outputs);
    let fname = format_ident!("{}", spec.name);
    let vis = if spec.public { quote!(pub) } else { quote!() };
    // One attribute per line, so that prettyplease prints `///` lines.
    let doc: Vec<String> = spec
        .doc
        .lines()
        .map(|l| if l.is_empty() { String::new() } else { format!(" {l}") })
        .collect();
    let ret = &spec.ret;
    let in_place = matches!(spec.output, Output::InPlace { .. });
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
    let emitted = |body: TokenStream| Emitted {
        method: quote! {
            #(#[doc = #doc])*
            #[doc = ""]
            #[doc = #op_doc]
            #[inline]
            #vis fn #fname<S: ::dyngen::Scalar>(#(#params,)* #out_param) #ret_ty {
                #home::#fname::#fname(#(#arg_names,)* #out_arg)
            }
        },
        body: quote! {
            pub mod #fname {
                #body
            }
        },
    };
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
    // that are constants or inputs (made up front). A computed output stored in one
    // place and used nowhere else is written straight there, without a `let`.
    let mut slots: HashMap<NodeId, Vec<usize>> = HashMap::new();
    let mut early_stores = Vec::new();
    let mut direct: HashMap<NodeId, usize> = HashMap::new();
    if let Output::InPlace { place, clear, views } = &spec.output {
        let computed: HashSet<NodeId> = stmts.iter().flat_map(|s| s.defines.iter().copied()).collect();
        let names = Names {
            spill: &HashMap::new(),
            args: &spec.args,
            inlined: &inlined,
        };
        let is_zero = |o: NodeId| graph.node(o) == Node::Const(0.0f64.to_bits());
        if spec.outputs.iter().any(|&o| is_zero(o)) {
            early_stores.push(clear.clone());
        }
        early_stores.push(views.clone());
        for (k, &o) in spec.outputs.iter().enumerate() {
            if computed.contains(&o) {
                slots.entry(o).or_default().push(k);
            } else if !is_zero(o) {
                let (p, x) = (place(k), names.operand(graph, o));
                early_stores.push(quote!(#p = #x;));
            }
        }
        let mut used = HashSet::new();
        for s in &stmts {
            let mut leaves = Vec::new();
            inlined.leaves(graph, &s.node, &mut leaves);
            used.extend(leaves);
        }
        for s in &stmts {
            let d = s.defines[0];
            if s.defines.len() == 1 && !used.contains(&d) {
                if let Some([k]) = slots.get(&d).map(Vec::as_slice) {
                    direct.insert(d, *k);
                }
            }
        }
    }
    let sections = Sections::new(graph);
    let write = |s: &Stmt, names: &Names<'_>| -> TokenStream {
        let Output::InPlace { place, .. } = &spec.output else {
            return emit_stmt(graph, s, names);
        };
        if let Some(&k) = direct.get(&s.defines[0]) {
            let p = place(k);
            let x = names.node_expr(graph, s.node).0;
            return quote!(#p = #x;);
        }
        let st = emit_stmt(graph, s, names);
        let stores = s.defines.iter().flat_map(|d| {
            let x = var(*d);
            slots.get(d).into_iter().flatten().map(move |&k| {
                let p = place(k);
                quote!(#p = #x;)
            })
        });
        quote!(#st #(#stores)*)
    };

    if chunks.len() == 1 {
        let names = Names {
            spill: &HashMap::new(),
            args: &spec.args,
            inlined: &inlined,
        };
        let mut current = None;
        let body: Vec<TokenStream> = chunks[0]
            .iter()
            .map(|s| {
                let marker = sections.marker(s, &mut current);
                let st = write(s, &names);
                quote!(#marker #st)
            })
            .collect();
        let returned: HashSet<NodeId> = match &spec.output {
            Output::Return(_) => spec.outputs.iter().copied().collect(),
            Output::InPlace { .. } => HashSet::new(),
        };
        let body = grouped(chunks[0], body, |s| reads(graph, &inlined, s), &returned);
        let value = match &spec.output {
            Output::Return(assemble) => {
                let outs: Vec<TokenStream> = spec.outputs.iter().map(|&o| names.operand(graph, o)).collect();
                assemble(&outs)
            }
            Output::InPlace { .. } => TokenStream::new(),
        };
        let body = quote! {
            pub fn #fname<S: ::dyngen::Scalar>(#(#params,)* #out_param) #ret_ty {
                #(#early_stores)*
                #(#body)*
                #value
            }
        };
        return (emitted(body), report);
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
    let reads = |s: &Stmt| reads(graph, &inlined, s);
    let mut spill: HashMap<NodeId, usize> = HashMap::new();
    let mark = |id: NodeId, spill: &mut HashMap<NodeId, usize>| {
        let next = spill.len();
        spill.entry(id).or_insert(next);
    };
    for (c, chunk) in chunks.iter().enumerate() {
        for s in chunk.iter() {
            for op in reads(s) {
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
    let views = match &spec.output {
        Output::InPlace { views, .. } => views.clone(),
        Output::Return(_) => TokenStream::new(),
    };
    let mut parts = Vec::new();
    let mut calls = Vec::new();
    for (c, chunk) in chunks.iter().enumerate() {
        let part = format_ident!("part{}", c);
        // Each part says which section it starts in.
        let mut current = None;
        let local: HashMap<NodeId, usize> = HashMap::new();
        let names = Names {
            spill: &local,
            args: &spec.args,
            inlined: &inlined,
        };
        // Loads of values defined in earlier parts.
        let mut loads: Vec<NodeId> = chunk
            .iter()
            .flat_map(reads)
            .filter(|op| defined_in.get(op).is_some_and(|&d| d < c))
            .collect();
        loads.sort_unstable();
        loads.dedup();
        let load_stmts = loads.iter().map(|&id| {
            let x = var(id);
            let k = usize_lit(spill[&id]);
            quote!(let #x = w[#k];)
        });
        let body: Vec<TokenStream> = chunk
            .iter()
            .map(|s| {
                let marker = sections.marker(s, &mut current);
                let st = write(s, &names);
                quote!(#marker #st)
            })
            .collect();
        let spilled: HashSet<NodeId> = chunk
            .iter()
            .flat_map(|s| s.defines.iter().copied())
            .filter(|id| spill.contains_key(id))
            .collect();
        let body = grouped(chunk, body, reads, &spilled);
        let spills = chunk.iter().flat_map(|s| s.defines.iter()).filter_map(|id| {
            spill.get(id).map(|&k| {
                let k = usize_lit(k);
                let x = var(*id);
                quote!(w[#k] = #x;)
            })
        });
        parts.push(quote! {
            #[inline(never)]
            fn #part<S: ::dyngen::Scalar>(#(#params,)* w: &mut [S; #width], #out_param) {
                #views
                #(#load_stmts)*
                #(#body)*
                #(#spills)*
            }
        });
        calls.push(quote!(#part(#(#arg_names,)* &mut w, #out_arg);));
    }
    let value = match &spec.output {
        Output::Return(assemble) => {
            let names = Names {
                spill: &spill,
                args: &spec.args,
                inlined: &inlined,
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
        Output::InPlace { .. } => TokenStream::new(),
    };
    let body = quote! {
        pub fn #fname<S: ::dyngen::Scalar>(#(#params,)* #out_param) #ret_ty {
            let mut w = [S::ZERO; #width];
            { #(#early_stores)* }
            #(#calls)*
            #value
        }
        #(#parts)*
    };
    (emitted(body), report)
}

/// The operands a statement reads from other statements, inputs and constants,
/// through the nodes written inside it.
fn reads(graph: &Graph, inlined: &Inlined, s: &Stmt) -> Vec<NodeId> {
    let mut leaves = Vec::new();
    inlined.leaves(graph, &s.node, &mut leaves);
    leaves
}

/// Statements per block of a grouped function body (see [`grouped`]).
const GROUP: usize = 100;

/// Function bodies up to this many statements are written flat, one `let` per
/// statement, as they read best.
const GROUPED_ABOVE: usize = 1000;

/// A function body of more than [`GROUPED_ABOVE`] statements, written as blocks of [`GROUP`]
/// statements that each hand on, as a tuple, the values read after them:
/// `let (x4, x9,) = { let x3 = ...; ...; (x4, x9,) };`.
///
/// Each `let` opens a scope nested in the one before, and rustc's debug-info emitter
/// overflows its stack on a few thousand nested scopes, in every build with debug
/// information (a 5,000-statement function crashes it). Blocks keep the nesting
/// to `n / GROUP + GROUP`, so a function of any length is one function: no parts, no
/// values stored between them. With optimisation the tuples cost nothing; the
/// operations and their order are unchanged.
///
/// `stmts` and `tokens` are the statements and their code, one each; `live_out` the
/// values read after the body.
fn grouped(
    stmts: &[Stmt],
    tokens: Vec<TokenStream>,
    reads: impl Fn(&Stmt) -> Vec<NodeId>,
    live_out: &HashSet<NodeId>,
) -> Vec<TokenStream> {
    if stmts.len() <= GROUPED_ABOVE {
        return tokens;
    }
    let mut last_read: HashMap<NodeId, usize> = HashMap::new();
    for (i, s) in stmts.iter().enumerate() {
        for op in reads(s) {
            let g = last_read.entry(op).or_default();
            *g = (*g).max(i / GROUP);
        }
    }
    let mut tokens = tokens.into_iter();
    let mut out = Vec::new();
    for (k, group) in stmts.chunks(GROUP).enumerate() {
        let body: Vec<TokenStream> = tokens.by_ref().take(group.len()).collect();
        let handed_on: Vec<Ident> = group
            .iter()
            .flat_map(|s| s.defines.iter())
            .filter(|&d| live_out.contains(d) || last_read.get(d).is_some_and(|&g| g > k))
            .map(|&d| var(d))
            .collect();
        out.push(if handed_on.is_empty() {
            quote!({ #(#body)* })
        } else {
            quote!(let (#(#handed_on,)*) = { #(#body)* (#(#handed_on,)*) };)
        });
    }
    out
}

/// The graph's sections ([`Graph::mark`]), to say in the code where each starts.
struct Sections {
    marks: Vec<(NodeId, String)>,
}

impl Sections {
    fn new(graph: &Graph) -> Sections {
        Sections {
            marks: graph.sections(),
        }
    }

    /// A marker statement before `s` when `s` opens a section other than `current`.
    /// The marker is a string-literal statement: it compiles to nothing, survives
    /// prettyplease (which drops comments), and [`comment_markers`] turns it into a
    /// `//` comment in the written file.
    fn marker(&self, s: &Stmt, current: &mut Option<usize>) -> TokenStream {
        let k = self.marks.partition_point(|(start, _)| *start <= s.defines[0]);
        let Some(k) = k.checked_sub(1) else {
            return TokenStream::new();
        };
        if *current == Some(k) {
            return TokenStream::new();
        }
        *current = Some(k);
        let label = &self.marks[k].1;
        quote!(#label;)
    }
}

/// Turns the section markers of emitted code (`"label";` alone on a line, as
/// prettyplease prints them) into `// label` comments after a blank line.
pub fn comment_markers(pretty: &str) -> String {
    let mut out = String::with_capacity(pretty.len());
    for line in pretty.lines() {
        let body = line.trim_start();
        let label = body
            .strip_prefix('"')
            .and_then(|b| b.strip_suffix("\";"))
            .filter(|l| !l.contains(['"', '\\']));
        match label {
            Some(label) => {
                let indent = &line[..line.len() - body.len()];
                if !out.ends_with("{\n") {
                    out.push('\n');
                }
                out.push_str(&format!("{indent}// {label}\n"));
            }
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    out
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
    inlined: &'a Inlined,
}

/// Binding strength of an emitted expression: sums, products, negations, atoms.
const SUM: u8 = 1;
const PRODUCT: u8 = 2;
const UNARY: u8 = 3;
const ATOM: u8 = 4;

impl Names<'_> {
    /// The expression computing `node`, with the operands written inside it in
    /// parentheses where Rust's precedence and left-to-right grouping would otherwise
    /// change the order of operations; and how strongly it binds.
    fn node_expr(&self, graph: &Graph, node: Node) -> (TokenStream, u8) {
        let op = |id: NodeId, min: u8| {
            let (e, p) = self.inner(graph, id);
            if p < min {
                quote!((#e))
            } else {
                e
            }
        };
        if let Some(fused) = self.fused(graph, node) {
            return (fused, ATOM);
        }
        match node {
            // The right operand of `-` and `/` (and, to keep the graph's grouping
            // exactly, of `+` and `*`) must bind more strongly than the operator.
            Node::Add(a, b) => {
                let (a, b) = (op(a, SUM), op(b, PRODUCT));
                (quote!(#a + #b), SUM)
            }
            Node::Sub(a, b) => {
                let (a, b) = (op(a, SUM), op(b, PRODUCT));
                (quote!(#a - #b), SUM)
            }
            Node::Mul(a, b) => {
                let (a, b) = (op(a, PRODUCT), op(b, UNARY));
                (quote!(#a * #b), PRODUCT)
            }
            Node::Div(a, b) => {
                let (a, b) = (op(a, PRODUCT), op(b, UNARY));
                (quote!(#a / #b), PRODUCT)
            }
            Node::Neg(a) => {
                let a = op(a, ATOM);
                (quote!(-#a), UNARY)
            }
            Node::Sin(a) => {
                let a = op(a, SUM);
                (quote!(S::sin(#a)), ATOM)
            }
            Node::Cos(a) => {
                let a = op(a, SUM);
                (quote!(S::cos(#a)), ATOM)
            }
            Node::Const(_) | Node::Input { .. } => (TokenStream::new(), ATOM),
        }
    }

    /// A sum or difference with a product written inside it ([`Inlined`]) as
    /// `Scalar::mul_add`, the right operand's product first: `a + x y` and `x y + b`
    /// are `mul_add(x, y, ·)`, `a − x y` is `mul_add(−x, y, a)`, `x y − b` is
    /// `mul_add(x, y, −b)`. Negation and the order of a sum's operands are exact, so
    /// unfused these are the same values as the sum or difference.
    fn fused(&self, graph: &Graph, node: Node) -> Option<TokenStream> {
        let product = |id: NodeId| match graph.node(id) {
            Node::Mul(x, y) if self.inlined.contains(id) => Some((x, y)),
            _ => None,
        };
        let arg = |id: NodeId| self.inner(graph, id).0;
        let negated = |id: NodeId| {
            let (e, p) = self.inner(graph, id);
            if p < ATOM {
                quote!(-(#e))
            } else {
                quote!(-#e)
            }
        };
        let mul_add = |x: TokenStream, y: TokenStream, z: TokenStream| quote!(S::mul_add(#x, #y, #z));
        match node {
            Node::Add(a, b) => match (product(a), product(b)) {
                (_, Some((x, y))) => Some(mul_add(arg(x), arg(y), arg(a))),
                (Some((x, y)), None) => Some(mul_add(arg(x), arg(y), arg(b))),
                (None, None) => None,
            },
            Node::Sub(a, b) => match (product(a), product(b)) {
                (_, Some((x, y))) => Some(mul_add(negated(x), arg(y), arg(a))),
                (Some((x, y)), None) => Some(mul_add(arg(x), arg(y), negated(b))),
                (None, None) => None,
            },
            _ => None,
        }
    }

    /// An operand: written out if it is inlined, else by name.
    fn inner(&self, graph: &Graph, id: NodeId) -> (TokenStream, u8) {
        if self.inlined.contains(id) {
            return self.node_expr(graph, graph.node(id));
        }
        let e = self.operand(graph, id);
        // A negative constant is `from_f64(-x)`, a call: an atom.
        (e, ATOM)
    }

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
        return quote!(S::ZERO);
    }
    let lit = float_literal(x.abs());
    if x.is_sign_negative() && x != 0.0 {
        quote!(S::from_f64(-#lit))
    } else {
        quote!(S::from_f64(#lit))
    }
}

fn emit_stmt(graph: &Graph, s: &Stmt, names: &Names<'_>) -> TokenStream {
    let x = var(s.defines[0]);
    match s.node {
        Node::Sin(a) if s.defines.len() == 2 => {
            let c = var(s.defines[1]);
            let a = names.operand(graph, a);
            quote!(let (#x, #c) = S::sin_cos(#a);)
        }
        Node::Const(_) | Node::Input { .. } => TokenStream::new(),
        node => {
            let e = names.node_expr(graph, node).0;
            quote!(let #x = #e;)
        }
    }
}

/// A `usize` literal for array lengths in emitted signatures.
pub fn usize_lit(n: usize) -> Literal {
    Literal::usize_unsuffixed(n)
}

/// An unsuffixed float literal spelling `x` (finite, not negative) with the fewest
/// digits that read back as exactly `x` (`{:?}`, with an exponent for very large or
/// small magnitudes). Nothing is rounded here to look nicer: a constant such as
/// `0.0018913546875000001` is the value the description wrote or the model's own
/// arithmetic produced, and printing a shorter neighbour would change the results.
/// The one place where rounding noise is removed is the base-parameter analysis,
/// whose factorisation error is far larger than the snap (`base::clean`).
fn float_literal(x: f64) -> Literal {
    format!("{x:?}").parse().unwrap_or_else(|_| Literal::f64_unsuffixed(x))
}

/// An `f64` literal for constant tables (no scalar conversion).
pub fn f64_lit(x: f64) -> TokenStream {
    let lit = float_literal(x.abs());
    if x.is_sign_negative() && x != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain of `n` links, each reading the one before; the output adds the chain's
    /// end to its sixth link, which nothing else reads. Returns the body, the report
    /// and the sixth link's name.
    fn chain_fn(g: &Graph, n: usize) -> (String, FnReport, String) {
        let (a, b) = (g.input(0, 0), g.input(0, 1));
        let mut links = vec![a * b];
        for _ in 1..n {
            let last = *links.last().unwrap();
            links.push(last * a + b);
        }
        let out = (*links.last().unwrap() + links[5]).id();
        let spec = FnSpec {
            name: "chain",
            public: true,
            doc: String::new(),
            args: vec![Arg {
                id: 0,
                name: "q",
                len: 2,
            }],
            ret: quote!(S),
            output: Output::Return(Box::new(|o: &[TokenStream]| o[0].clone())),
            outputs: vec![out],
        };
        let (emitted, report) = emit_fn(g, &spec, usize::MAX, &format_ident!("home"));
        (emitted.body.to_string(), report, var(links[5].id()).to_string())
    }

    #[test]
    fn long_bodies_are_blocks_that_hand_on_only_what_is_read_later() {
        let g = Graph::new();
        let (code, report, sixth) = chain_fn(&g, 2500);
        assert_eq!(report.parts, 1);
        assert!(report.statements > GROUPED_ABOVE, "{} statements", report.statements);
        // One block per 100 statements. Each hands on one value, the link the next
        // block reads (the last block: the returned value); the first also hands on
        // the sixth link, read only at the end.
        let tuples: Vec<Vec<&str>> = code
            .split("let (")
            .skip(1)
            .map(|t| {
                t[..t.find(") =").unwrap()]
                    .split(',')
                    .map(str::trim)
                    .filter(|n| !n.is_empty())
                    .collect()
            })
            .collect();
        assert_eq!(tuples.len(), report.statements.div_ceil(GROUP));
        assert_eq!(tuples[0].len(), 2);
        assert!(tuples[0].contains(&sixth.as_str()), "{:?}", tuples[0]);
        assert!(tuples[1..].iter().all(|t| t.len() == 1), "{tuples:?}");
    }

    #[test]
    fn short_bodies_stay_flat() {
        let g = Graph::new();
        let (code, report, _) = chain_fn(&g, 600);
        assert!(report.statements <= GROUPED_ABOVE);
        assert!(!code.contains("let ("));
    }
}
