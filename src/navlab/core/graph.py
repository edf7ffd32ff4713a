"""The node/topic graph (rqt_graph's picture) as data, Graphviz DOT, and SVG laid out by Graphviz's ``dot``."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from navlab.core.errors import CoreError
from navlab.core.executor import Executor
from navlab.io.files import write_text_atomic

HIDDEN_NODES = ("/_tf_buffer",)


@dataclass
class Graph:
    """Which nodes publish and subscribe to which topics."""

    nodes: list[str] = field(default_factory=list)
    topics: dict[str, tuple[list[str], list[str]]] = field(default_factory=dict)  # topic -> (pubs, subs)

    @classmethod
    def from_executor(cls, ex: Executor) -> Graph:
        """The live graph of an executor."""
        topics = {
            name: (sorted(set(t.publishers)), sorted({s.node for s in t.subscriptions if s.node not in HIDDEN_NODES}))
            for name, t in sorted(ex.topics.items())
        }
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

    def to_dot(self) -> str:
        """Graphviz DOT as rqt_graph draws it: nodes as ellipses, topics as boxes, edges publisher → topic →
        subscriber, left to right. A node and a topic of the same name stay two vertices (ids ``n:``/``t:``)."""

        def q(text: str) -> str:
            return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'

        lines = ["digraph navlab {", "  rankdir=LR;", '  node [fontname="Helvetica", fontsize=10];',
                 '  edge [color="#555555"];']  # fmt: skip
        for n in self.nodes:
            lines.append(f"  {q('n:' + n)} [label={q(n)}, shape=ellipse];")
        for t, (pubs, subs) in self.topics.items():
            lines.append(f"  {q('t:' + t)} [label={q(t)}, shape=box];")
            lines += [f"  {q('n:' + p)} -> {q('t:' + t)};" for p in pubs]
            lines += [f"  {q('t:' + t)} -> {q('n:' + s)};" for s in subs]
        lines.append("}")
        return "\n".join(lines) + "\n"

    def write_svg(self, path: str | Path) -> None:
        """Lay the graph out with Graphviz's ``dot`` (layered, cycles handled, as rqt_graph does) and write the
        SVG atomically. Raises CoreError when ``dot`` is not installed."""
        svg = self.to_svg()
        write_text_atomic(Path(path), svg)

    def to_svg(self) -> str:
        """The SVG text of :meth:`to_dot` laid out by Graphviz's ``dot``."""
        import shutil
        import subprocess

        dot = shutil.which("dot")
        if dot is None:
            raise CoreError("Graphviz's `dot` is not installed, so the graph cannot be laid out "
                            "(Debian: sudo apt-get install graphviz); the .dot file is written")  # fmt: skip
        proc = subprocess.run([dot, "-Tsvg"], input=self.to_dot(), capture_output=True, text=True, timeout=60,
                              check=False)  # fmt: skip
        if proc.returncode != 0:
            raise CoreError(f"dot failed to lay out the graph: {proc.stderr.strip()}")
        return proc.stdout
