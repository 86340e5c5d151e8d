//! `dyngen info`: what dyngen sees in a URDF.

use crate::common::{load_model, out, with_spinner, ModelArgs, Progress, Result};
use dyngen_codegen::{analyse_model, analyse_rigid, generate, Options};
use dyngen_model::graph::{incidence, path_matrix};
use dyngen_model::Model;
use std::fmt::Write as _;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples:
  dyngen info robots/ur5/ur5.urdf
  dyngen info robots/ur5/ur5.urdf --no-ops          # skip code generation (faster)
  dyngen info arm.urdf --gravity 0 -9.81 0";

#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// The robot description (URDF, or MJCF as `.xml`).
    pub urdf: PathBuf,

    #[command(flatten)]
    pub gravity: ModelArgs,

    /// Skip the operation counts (they need a full code generation, which takes a
    /// few seconds for a 6–7 DOF arm; the base parameters do not).
    #[arg(long)]
    pub no_ops: bool,
}

pub fn run(args: &InfoArgs, progress: &Progress) -> Result<()> {
    let model = load_model(&args.urdf, &args.gravity)?;
    let mut out = topology(&model, &args.urdf);
    let n = model.dof();
    writeln!(out).ok();
    writeln!(out, "Parameters").ok();
    writeln!(
        out,
        "  standard (m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz per body): 10n = {}",
        10 * n
    )
    .ok();
    writeln!(
        out,
        "  principal (m, J1, J2, J3 per body):                        4n = {}",
        4 * n
    )
    .ok();
    if n == 0 {
        out!("{out}");
        return Ok(());
    }
    // Generation (the operation counts) needs the joint parameters' base too; what is
    // printed does not.
    let (base, pbase, bases) = with_spinner(progress, "finding the base parameters", || {
        if args.no_ops {
            let (standard, principal) = analyse_rigid(&model);
            (standard, principal, None)
        } else {
            let bases = analyse_model(&model);
            (bases.standard.clone(), bases.principal.clone(), Some(bases))
        }
    });
    let (base, pbase) = (&base, &pbase);
    writeln!(
        out,
        "  base (identifiable from joint torques):                    {}",
        base.count()
    )
    .ok();
    writeln!(
        out,
        "  principal base:                                            {}",
        pbase.count()
    )
    .ok();
    for (title, b) in [
        ("Base parameters (standard)", base),
        ("Base parameters (principal)", pbase),
    ] {
        writeln!(out).ok();
        let note = match (b.confirmed, b.rank_check == b.count()) {
            (true, true) => String::new(),
            (false, _) => " (not confirmed by a second random seed)".to_string(),
            (true, false) => format!(" (the singular values give rank {} instead)", b.rank_check),
        };
        writeln!(out, "{title}{note}").ok();
        for (k, g) in b.groupings.iter().enumerate() {
            writeln!(out, "  {:>3}  {g}", k + 1).ok();
        }
    }
    let Some(bases) = bases else {
        // --no-ops
        out!("{out}");
        return Ok(());
    };
    if let Some(why) = dyngen_codegen::unsupported(&model) {
        writeln!(out).ok();
        writeln!(out, "Generated functions: none ({why})").ok();
        out!("{out}");
        return Ok(());
    }
    let generated = with_spinner(progress, "generating code for the op counts", || {
        generate(&model, "Robot", &bases, &Options::default())
    });
    writeln!(out).ok();
    writeln!(out, "Generated functions (operation counts)").ok();
    for line in generated.op_report().lines() {
        writeln!(out, "  {line}").ok();
    }
    out!("{out}");
    Ok(())
}

fn topology(model: &Model, path: &std::path::Path) -> String {
    let n = model.dof();
    let mut out = String::new();
    let g = model.gravity;
    writeln!(out, "Robot `{}` from {}", model.name, path.display()).ok();
    writeln!(
        out,
        "  {n} moving bodies, {n} joints, base link `{}`, gravity [{}, {}, {}] m/s²",
        model.base, g[0], g[1], g[2]
    )
    .ok();
    if model.multi_dof_joint().is_some() {
        writeln!(
            out,
            "  {} position coordinates, {} velocity coordinates{}",
            model.nq(),
            model.nv(),
            if model.is_floating() {
                " (floating base: joint 1 is a free flyer)"
            } else {
                ""
            }
        )
        .ok();
    }
    if model.mimic_joint().is_some() {
        writeln!(
            out,
            "  {} velocity coordinates; joints that follow another (<mimic>), q = multiplier · q_leader + offset:",
            model.nv()
        )
        .ok();
        for j in &model.joints {
            if let Some(m) = j.mimic {
                let leader = &model.joints[m.leader - 1].name;
                writeln!(out, "    {} = {} · {leader} + {}", j.name, m.multiplier, m.offset).ok();
            }
        }
    }
    writeln!(out).ok();
    writeln!(out, "Joints (joint j carries body j; parent 0 is the base)").ok();
    // Capped at the longest name a description may give: a longer one (from a model
    // built in code) overflows its column, where a width of 65,536 or more would
    // panic the formatter.
    const MAX_NAME: usize = dyngen_model::xml::MAX_NAME_CHARS;
    let width = model
        .joints
        .iter()
        .map(|j| j.name.chars().count())
        .max()
        .unwrap_or(4)
        .clamp(4, MAX_NAME);
    writeln!(
        out,
        "  {:>3}  {:<width$}  {:<10}  {:>6}  {:<24}  limits",
        "j", "name", "type", "parent", "axis"
    )
    .ok();
    for (k, j) in model.joints.iter().enumerate() {
        let axis = if j.kind.has_axis() {
            format!("[{}, {}, {}]", j.axis[0], j.axis[1], j.axis[2])
        } else {
            "—".to_string()
        };
        let limits = match j.limits {
            Some(l) => format!("[{}, {}], v ≤ {}, effort ≤ {}", l.lower, l.upper, l.velocity, l.effort),
            None => "—".to_string(),
        };
        writeln!(
            out,
            "  {:>3}  {:<width$}  {:<10}  {:>6}  {:<24}  {limits}",
            k + 1,
            j.name,
            j.kind.urdf_name(),
            j.parent,
            axis
        )
        .ok();
    }
    writeln!(out).ok();
    writeln!(out, "Bodies").ok();
    let width = model
        .bodies
        .iter()
        .map(|b| b.name.chars().count())
        .max()
        .unwrap_or(4)
        .clamp(4, MAX_NAME);
    writeln!(
        out,
        "  {:>3}  {:<width$}  {:>10}  merged fixed links",
        "i", "name", "mass/kg"
    )
    .ok();
    writeln!(out, "  {:>3}  {:<width$}  {:>10}  (base)", 0, model.base, "—").ok();
    for (k, b) in model.bodies.iter().enumerate() {
        let merged = if b.merged.is_empty() {
            "—".to_string()
        } else {
            b.merged.join(", ")
        };
        writeln!(
            out,
            "  {:>3}  {:<width$}  {:>10.4}  {merged}",
            k + 1,
            b.name,
            b.inertial.mass
        )
        .ok();
    }
    if n > 0 {
        writeln!(out).ok();
        writeln!(
            out,
            "Incidence matrix S (rows bodies 0 = base, 1..{n}; columns joints 1..{n})"
        )
        .ok();
        out.push_str(&matrix(&incidence(model), 0));
        writeln!(out).ok();
        writeln!(out, "Path matrix T = S⁻¹ (rows joints 1..{n}; columns bodies 1..{n})").ok();
        out.push_str(&matrix(&path_matrix(model), 1));
    }
    out
}

/// An integer matrix with row labels starting at `first_row`.
fn matrix(m: &[Vec<i8>], first_row: usize) -> String {
    let mut out = String::new();
    for (r, row) in m.iter().enumerate() {
        let cells: Vec<String> = row.iter().map(|x| format!("{x:>2}")).collect();
        writeln!(out, "  {:>3} [{} ]", r + first_row, cells.join(" ")).ok();
    }
    out
}
