"""How closely two correct double-precision implementations can agree on `M⁻¹` and
the forward-dynamics derivatives of a floating robot: the conditioning of `M`.

Reads a floating-base fixture (`tests/fixtures/floating/*.json`, made by
`make_floating_fixtures.py` with Pinocchio) and, per sample, prints the 2-norm
condition number of Pinocchio's `M`, then how far Pinocchio's own `M⁻¹` and
`∂q̈/∂q = −M⁻¹ ∂τ/∂q` are from the same quantities computed from the same `M` and
`∂τ/∂q` in extended precision (numpy's `longdouble`, 64-bit mantissa), in the tests'
metric `‖x − y‖∞ / ‖y‖∞`. `∂τ/∂q` at `a = q̈` comes from Pinocchio
(`computeRNEADerivatives`), so the script runs in Pinocchio's environment:

    $PIN_HOME/.venv/bin/python scripts/forward_derivative_conditioning.py tests/fixtures/floating/humanoid31.json

With `--write`, also writes the extended-precision `M⁻¹` and `∂q̈/∂q` of each sample,
rounded to double, beside the fixture (`humanoid31.json` → `humanoid31_extended.json`),
for `tests/tests/integration/floating.rs` to measure dyngen against.
"""

import json
import sys

import os

import numpy as np
import pinocchio as pin

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def inverse_extended(m):
    """Gauss-Jordan with partial pivoting in np.longdouble."""
    n = m.shape[0]
    a = np.hstack([m.astype(np.longdouble), np.eye(n, dtype=np.longdouble)])
    for k in range(n):
        p = k + int(np.argmax(np.abs(a[k:, k])))
        a[[k, p]] = a[[p, k]]
        a[k] /= a[k, k]
        for i in range(n):
            if i != k:
                a[i] -= a[i, k] * a[k]
    return a[:, n:]


def pinocchio_q(model, ours):
    """dyngen's q (one angle per continuous joint) as Pinocchio's (cos, sin)."""
    q, k = [], 0
    for j in model.joints[1:]:
        if j.nq == 2:
            q += [np.cos(ours[k]), np.sin(ours[k])]
            k += 1
        else:
            q += ours[k:k + j.nq]
            k += j.nq
    return np.array(q)


def rel(x, y):
    y = np.asarray(y, dtype=np.longdouble)
    return float(np.max(np.abs(np.asarray(x, dtype=np.longdouble) - y)) / np.max(np.abs(y)))


def main(path, write):
    fx = json.load(open(path))
    extended = []
    print(f"{path}: {fx['urdf']}, root joint {fx.get('root_joint')}")
    model = pin.buildModelFromUrdf(os.path.join(ROOT, fx["urdf"]), pin.JointModelFreeFlyer())
    data = model.createData()
    print("sample  cond(M)   Pinocchio M⁻¹ vs extended   Pinocchio ∂q̈/∂q vs extended")
    for s, sample in enumerate(fx["samples"]):
        m = np.array(sample["M"], dtype=float)
        minv = inverse_extended(m)
        q = pinocchio_q(model, sample["q"])
        v, ddq = np.array(sample["v"]), np.array(sample["ddq"])
        dq, _, _ = (x.copy() for x in pin.computeRNEADerivatives(model, data, q, v, ddq))
        dq = dq.astype(np.longdouble)
        ddq_dq = -minv @ dq
        extended.append({"Minv": minv.astype(float).tolist(), "ddq_dq": ddq_dq.astype(float).tolist()})
        print(
            f"{s:6d}  {np.linalg.cond(m):8.2e}  {rel(sample['Minv'], minv):26.2e}  "
            f"{rel(sample['ddq_dq'], ddq_dq):28.2e}"
        )


    if write:
        out = path.replace(".json", "_extended.json")
        doc = {
            "generator": "scripts/forward_derivative_conditioning.py --write",
            "source": os.path.relpath(path, ROOT),
            "what": "M⁻¹ of the source's M and −M⁻¹ ∂τ/∂q (Pinocchio's, at a = ddq) in np.longdouble",
            "samples": extended,
        }
        with open(out, "w") as f:
            json.dump(doc, f)
        print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1], "--write" in sys.argv[2:])
