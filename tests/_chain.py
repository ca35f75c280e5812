"""The chain of issue 43, shared by the calculus tests and bench/compose_pacti.py.

Node ``N<i>`` (``i = 0 .. n-1``) reads ``x<i>`` and writes ``x<i+1>``; it
assumes ``0 <= x_i <= 100`` and guarantees ``x_{i+1} <= x_i + 1`` and
``0 <= x_{i+1}``; the environment gives ``0 <= x0 <= 50`` (a plan fact of
``N0``).  In context ``x_i <= 50 + i``, so every assumption holds for
``n <= 51`` although no producer's guarantee alone entails its consumer's.
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

DODO = '''from pathlib import Path

from rclverify.app.tasks import build_tasks, doit_config

DOIT_CONFIG = doit_config()

globals().update(build_tasks(Path(__file__).parent))
'''


def chain_rcl(n: int, *, weak: dict[int, int] | None = None, missing: Sequence[int] = (), typ: str = "REAL",
              bound: int = 100) -> str:
    """The RCL text of the chain: ``weak`` maps a node index to the slope
    constant of its first guarantee (``x_{i+1} <= x_i + c``, default 1);
    the nodes in ``missing`` are declared with their interface only;
    ``bound`` is the upper bound of every assumption (100 in the issue)."""
    out = []
    for i in range(n):
        head = f"node N{i} {{\n  inputs( x{i} : {typ} )\n  outputs( x{i + 1} : {typ} )\n"
        if i in missing:
            out.append(head + "}\n")
            continue
        c = (weak or {}).get(i, 1)
        out.append(head + f"  assume( 0 <= in.x{i} and in.x{i} <= {bound} )\n"
                          f"  guarantee( out.x{i + 1} <= in.x{i} + {c} )\n"
                          f"  guarantee( 0 <= out.x{i + 1} )\n}}\n")
    return "\n".join(out)


def chain_plan(requirements: Sequence[tuple[str, str]] = (), x0_max: int = 50) -> str:
    """The plan: the chain's contract file, the environment fact of ``N0``
    and the formal requirements ``(id, formula)``."""
    lines = ["name: chain", "contracts:", "  - contracts/chain.rcl"]
    if requirements:
        lines.append("requirements:")
        for rid, formal in requirements:
            lines += [f"  - id: {rid}", f"    text: {rid} of the chain.", f'    formal: "{formal}"']
    lines += ["environment:", "  N0:", "    facts:", f'      - "0 <= in.x0 and in.x0 <= {x0_max}"']
    return "\n".join(lines) + "\n"


def write_chain(root: Path, n: int, *, requirements: Sequence[tuple[str, str]] = (), x0_max: int = 50,
                **kw: object) -> Path:
    """A workspace of the chain at ``root`` (contracts, plan, dodo.py)."""
    (root / "contracts").mkdir(parents=True, exist_ok=True)
    (root / "contracts/chain.rcl").write_text(chain_rcl(n, **kw), encoding="utf-8")  # type: ignore[arg-type]
    (root / "contracts/plan.yaml").write_text(chain_plan(requirements, x0_max), encoding="utf-8")
    (root / "dodo.py").write_text(DODO, encoding="utf-8")
    return root


#: The plan's evidence for the two-node chain of :func:`write_chain_with_evidence`.
EVIDENCE_PLAN = """nodes:
  N1:
    evidence:
      - {backend: property_tests, implementation: impl/n1.py:n1, max_examples: 10}
"""


def write_chain_with_evidence(root: Path) -> Path:
    """The chain of two nodes with property tests of ``N1`` (an implementation adding 1): a workspace
    with one evidence task, verified in about 3 s."""
    write_chain(root, 2)
    (root / "impl").mkdir()
    (root / "impl" / "n1.py").write_text("def n1(x1: float) -> dict[str, float]:\n    return {'x2': x1 + 1}\n")
    plan = root / "contracts" / "plan.yaml"
    plan.write_text(plan.read_text() + EVIDENCE_PLAN)
    return root
