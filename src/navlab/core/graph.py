"""The node/topic graph (rqt_graph's picture) as data, Graphviz DOT, and SVG laid out by Graphviz's ``dot``."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from navlab.core.errors import CoreError
from navlab.core.executor import Executor
from navlab.io import write_text_atomic

HIDDEN_NODES = ("/_tf_buffer",)


@dataclass
class Graph:
    """Which nodes publish and subscribe to which topics."""

    nodes: list[str] = field(default_factory=list)
    topics: dict[str, tuple[list[str], list[str]]] = field(default_factory=dict)  # topic -> (pubs, subs)

    @classmethod
    def from_executor(cls, ex: Executor) -> Graph:
        """The live graph of an executor."""

        def subscribers(name: str, t: Any) -> list[str]:
            subs = {s.node for s in t.subscriptions if s.node not in HIDDEN_NODES}
            return sorted(subs | ex.tf_listeners if name in ("/tf", "/tf_static") else subs)

        topics = {name: (sorted(set(t.publishers)), subscribers(name, t)) for name, t in sorted(ex.topics.items())}
        return cls(nodes=sorted(ex.nodes), topics=topics)

    def to_json(self) -> dict[str, object]:
        """JSON-able form (stored in recordings)."""
        return {"nodes": self.nodes, "topics": {k: {"pub": p, "sub": s} for k, (p, s) in self.topics.items()}}

    @classmethod
    def from_json(cls, data: dict[str, object]) -> Graph:
        """Inverse of :meth:`to_json`."""
        nodes, topics = data.get("nodes", []), data.get("topics", {})
        assert isinstance(nodes, list) and isinstance(topics, dict)
        return cls(
            nodes=list(nodes),
            topics={k: (list(v["pub"]), list(v["sub"])) for k, v in topics.items()},
        )

    def to_dot(self, *, rate_line: bool = False) -> str:
        """Graphviz DOT as rqt_graph draws it: nodes as ellipses, topics as boxes, edges publisher → topic →
        subscriber, left to right. A node and a topic of the same name stay two vertices (ids ``n:``/``t:``).
        ``rate_line``: topic boxes leave room for a second line (the viewer writes the rate there)."""

        def q(text: str) -> str:
            return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'

        lines = [
            "digraph navlab {",
            "  rankdir=LR;",
            '  node [fontname="Helvetica", fontsize=10];',
            '  edge [color="#555555"];',
        ]
        for n in self.nodes:
            lines.append(f"  {q('n:' + n)} [label={q(n)}, shape=ellipse];")
        for t, (pubs, subs) in self.topics.items():
            label = q(t)[:-1] + '\\n000.00 Hz"' if rate_line else q(t)  # dot's line break: backslash n
            lines.append(f"  {q('t:' + t)} [label={label}, shape=box];")
            lines += [f"  {q('n:' + p)} -> {q('t:' + t)};" for p in pubs]
            lines += [f"  {q('t:' + t)} -> {q('n:' + s)};" for s in subs]
        lines.append("}")
        return "\n".join(lines) + "\n"

    def write_svg(self, path: str | Path) -> None:
        """Lay the graph out with Graphviz's ``dot`` (layered, cycles handled, as rqt_graph does) and write the
        SVG atomically. Raises CoreError when ``dot`` is not installed."""
        svg = self.to_svg()
        write_text_atomic(Path(path), svg)

    def without_topics(self, hidden: tuple[str, ...]) -> Graph:
        """The same graph without the ``hidden`` topics (and topics nobody publishes or subscribes)."""
        return Graph(
            nodes=list(self.nodes),
            topics={t: ps for t, ps in self.topics.items() if t not in hidden and (ps[0] or ps[1])},
        )

    def layout(self) -> dict[str, Any]:
        """Graphviz ``dot``'s layered layout, for drawing in the viewer: ``width``/``height`` and each vertex's
        centre and size (``vertices``: name -> {kind, x, y, w, h}) in points, y down; each edge's cubic Bézier
        control points (``edges``: {tail, head, points}). Raises CoreError without ``dot``."""
        import shlex

        plain = self._dot("plain", rate_line=True)
        out: dict[str, Any] = {"width": 0.0, "height": 0.0, "vertices": {}, "edges": []}
        height = 0.0
        for line in plain.splitlines():
            f = shlex.split(line)
            if not f:
                continue
            if f[0] == "graph":
                out["width"], height = float(f[2]) * 72, float(f[3]) * 72
                out["height"] = height
            elif f[0] == "node":
                kind, name = f[1][0], f[1][2:]
                out["vertices"][f[1]] = {
                    "name": name,
                    "kind": "topic" if kind == "t" else "node",
                    "x": float(f[2]) * 72,
                    "y": height - float(f[3]) * 72,
                    "w": float(f[4]) * 72,
                    "h": float(f[5]) * 72,
                }
            elif f[0] == "edge":
                n = int(f[3])
                pts = [[float(f[4 + 2 * i]) * 72, height - float(f[5 + 2 * i]) * 72] for i in range(n)]
                out["edges"].append({"tail": f[1], "head": f[2], "points": pts})
        return out

    def _dot(self, fmt: str, *, rate_line: bool = False) -> str:
        """:meth:`to_dot` run through Graphviz's ``dot -T<fmt>``."""
        import shutil
        import subprocess

        dot = shutil.which("dot")
        if dot is None:
            raise CoreError(
                "Graphviz's `dot` is not installed, so the graph cannot be laid out "
                "(Debian: sudo apt-get install graphviz)"
            )
        proc = subprocess.run(
            [dot, f"-T{fmt}"],
            input=self.to_dot(rate_line=rate_line),
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        if proc.returncode != 0:
            raise CoreError(f"dot failed to lay out the graph: {proc.stderr.strip()}")
        return proc.stdout

    def to_svg(self) -> str:
        """The SVG text of :meth:`to_dot` laid out by Graphviz's ``dot``."""
        return self._dot("svg")


PAGE_HIDDEN_TOPICS = ("/tf_static", "/clock", "/rosout")  # not drawn in the viewer's Graph panel


def with_layout(graph: dict[str, Any]) -> dict[str, Any]:
    """A graph's JSON (:meth:`Graph.to_json`, plus anything else) with ``layout``: dot's layout of it without
    ``PAGE_HIDDEN_TOPICS``, for the viewer's Graph panel; unchanged when Graphviz is missing (the page then
    draws its own columns)."""
    try:
        return {**graph, "layout": Graph.from_json(graph).without_topics(PAGE_HIDDEN_TOPICS).layout()}
    except CoreError:
        return graph
