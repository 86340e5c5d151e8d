#!/usr/bin/env bash
# Measures what a user pays to build a generated robot with every function in use:
# a fresh crate that depends on robots/CRATE and calls every `Robot` method in f64,
# built from scratch in release with its own target directory (all dependencies
# included). Prints the wall time and rustc's peak memory (GNU time's maximum
# resident set size of the whole build, i.e. of its largest process).
#
#   scripts/compile_everything.sh humanoid31 Humanoid31
#   scripts/compile_everything.sh panda Panda
#
# With KEEP_TARGET=DIR the build uses DIR as its target directory and keeps it: a
# second run then rebuilds only the robot crate and the binary (touch the URDF
# first), which is what a change to the robot costs.
set -euo pipefail
crate="$1"
ty="$2"
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/src"
cat > "$dir/Cargo.toml" <<EOF
[package]
name = "compile-everything"
version = "0.1.0"
edition = "2021"

[dependencies]
dyngen = { path = "$root/core" }
robot-$crate = { path = "$root/robots/$crate" }

[profile.release.build-override]
opt-level = 3
EOF
crate_ident="${crate//-/_}"
cat > "$dir/src/main.rs" <<EOF
use dyngen::{Coulomb, Pose, Robot, Wrench, BodyRegressor, FrameJacobian};
use robot_$crate_ident::$ty;

fn all<R: Robot>() -> f64 {
    let (nq, nv, nb) = (R::NQ, R::NV, R::NBODIES);
    let mut q = vec![0.1; nq];
    dyngen::configuration::normalize(&R::MODEL, &mut q).unwrap();
    let (v, a) = (vec![0.2; nv], vec![0.3; nv]);
    let p = R::nominal_params().to_vec();
    let jp = R::nominal_joint_params().to_vec();
    let c = Coulomb::Sign;
    let mut s = 0.0;
    let mut t = vec![0.0; nv];
    let mut m = vec![0.0; nv * nv];
    let mut y = vec![0.0; nv * (R::NPARAMS + R::NJOINT_PARAMS)];
    let mut poses = vec![Pose::default(); nb];
    let mut w = vec![Wrench::default(); nb];
    let mut br = vec![BodyRegressor::default(); nb];
    let mut beta = vec![0.0; R::NBASE + R::NBASE_PRINCIPAL + R::NBASE_JOINTS];
    R::rnea(&q, &v, &a, &p, &mut t); s += t[0];
    R::forward_kinematics(&q, &mut poses); s += poses[0].translation[0];
    R::joint_wrenches(&q, &v, &a, &p, &mut w); s += w[0].force[0];
    R::nonlinear_effects(&q, &v, &p, &mut t); s += t[0];
    R::generalized_gravity(&q, &p, &mut t); s += t[0];
    R::crba(&q, &p, &mut m); s += m[0];
    R::aba(&q, &v, &a, &p, &mut t); s += t[0];
    R::joint_torque_regressor(&q, &v, &a, &mut y[..nv * R::NPARAMS]); s += y[0];
    let mut yw = vec![0.0; 6 * nb * R::NPARAMS];
    R::joint_wrench_regressor(&q, &v, &a, &mut yw); s += yw[0];
    R::principal_regressor(&q, &v, &a, &mut y[..nv * R::NTHETA]); s += y[0];
    R::base_regressor(&q, &v, &a, &mut y[..nv * R::NBASE]); s += y[0];
    R::principal_base_regressor(&q, &v, &a, &mut y[..nv * R::NBASE_PRINCIPAL]); s += y[0];
    R::body_regressors(&q, &v, &a, &mut br); s += br[0].force[(0, 0)];
    R::body_resultants(&q, &v, &a, &p, &mut w); s += w[0].force[0];
    R::base_params(&p, &mut beta[..R::NBASE]); s += beta[0];
    let theta = R::nominal_theta().to_vec();
    R::principal_base_params(&theta, &mut beta[..R::NBASE_PRINCIPAL]); s += beta[0];
    R::rnea_joints(&q, &v, &a, &p, &jp, c, &mut t); s += t[0];
    R::crba_joints(&q, &p, &jp, &mut m); s += m[0];
    R::aba_joints(&q, &v, &a, &p, &jp, c, &mut t); s += t[0];
    R::torque_regressor_joints(&q, &v, &a, c, &mut y); s += y[0];
    R::base_regressor_joints(&q, &v, &a, c, &mut y[..nv * R::NBASE_JOINTS]); s += y[0];
    R::base_params_joints(&p, &jp, &mut beta[..R::NBASE_JOINTS]); s += beta[0];
    let mut jac = vec![0.0; 6 * nv];
    let mut jd = vec![0.0; 6 * nv];
    for f in 0..R::MODEL.frames.len() {
        s += R::frame_placement(&q, f).unwrap().translation[0];
        R::frame_jacobian(&q, f, dyngen::ReferenceFrame::LocalWorldAligned, &mut jac).unwrap();
        R::frame_jacobian_time_variation(&q, &v, f, dyngen::ReferenceFrame::World, &mut jac, &mut jd).unwrap();
        s += R::frame_motion(&q, &v, &a, f).unwrap().velocity.linear[0] + jac[0] + jd[0];
    }
    s += R::center_of_mass(&q, &p)[0];
    R::com_jacobian(&q, &p, &mut jac[..3 * nv]); s += jac[0];
    R::centroidal_map(&q, &p, &mut jac); s += jac[0];
    R::centroidal_map_time_variation(&q, &v, &p, &mut jac, &mut jd); s += jd[0];
    let (mut d1, mut d2, mut d3) = (vec![0.0; nv * nv], vec![0.0; nv * nv], vec![0.0; nv * nv]);
    R::rnea_derivatives(&q, &v, &a, &p, &mut d1, &mut d2, &mut d3); s += d1[0];
    R::aba_derivatives(&q, &v, &a, &p, &mut t, &mut d1, &mut d2, &mut d3); s += d1[0];
    R::inverse_inertia(&q, &p, &mut m); s += m[0];
    let _ = FrameJacobian::<f64, 1>::default();
    s
}

fn main() {
    println!("{}", all::<$ty>());
}
EOF
cd "$dir"
if [ -n "${KEEP_TARGET:-}" ]; then
    export CARGO_TARGET_DIR="$KEEP_TARGET"
    touch "$root/robots/$crate/$crate.urdf"
fi
target="${CARGO_TARGET_DIR:-target}"
/usr/bin/time -f "wall %e s, peak %M KB" cargo build --release --quiet --timings 2>&1 | tail -3
"$target/release/compile-everything" > /dev/null
echo "generated file: $(wc -l < "$(ls -t "$target"/release/build/robot-$crate-*/out/*.rs | head -1)") lines"
echo "unit times (s), longest first:"
python3 - "$target/cargo-timings/cargo-timing.html" <<'PY'
import json, re, sys
text = open(sys.argv[1]).read()
units = json.loads(re.search(r"const UNIT_DATA = (\[.*?\]);\n", text, re.S).group(1))
for u in sorted(units, key=lambda u: -u["duration"])[:6]:
    print(f"  {u['duration']:6.1f}  {u['name']} {u.get('target', '').strip()}")
PY
