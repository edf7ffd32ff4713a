"""The node/topic graph (rqt_graph's picture) as data, Graphviz DOT, and SVG drawn with matplotlib."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from navlab.core.executor import Executor
from navlab.io.files import save_figure_atomic

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
        """Graphviz DOT: nodes as ellipses, topics as boxes, edges publisher → topic → subscriber."""
        lines = ["digraph navlab {", "  rankdir=LR;", '  node [fontname="Helvetica"];']
        for n in self.nodes:
            lines.append(f'  "{n}" [shape=ellipse];')
        for t, (pubs, subs) in self.topics.items():
            lines.append(f'  "{t}" [shape=box];')
            lines += [f'  "{p}" -> "{t}";' for p in pubs]
            lines += [f'  "{t}" -> "{s}";' for s in subs]
        lines.append("}")
        return "\n".join(lines) + "\n"

    def layers(self) -> dict[str, int]:
        """A left-to-right layer for every graph vertex (longest path from sources, cycles cut)."""
        succ: dict[str, list[str]] = {v: [] for v in [*self.nodes, *self.topics]}
        for t, (pubs, subs) in self.topics.items():
            for p in pubs:
                succ.setdefault(p, []).append(t)
            succ[t] += subs
            for s in subs:
                succ.setdefault(s, [])
        layer = dict.fromkeys(succ, 0)
        for _ in range(len(succ)):  # Bellman-Ford-like relaxation, bounded so cycles terminate
            changed = False
            for v, outs in succ.items():
                for w in outs:
                    if layer[w] < layer[v] + 1 and layer[v] + 1 < len(succ):
                        layer[w] = layer[v] + 1
                        changed = True
            if not changed:
                break
        return layer

    def write_svg(self, path: str | Path) -> None:
        """Draw the graph (matplotlib, no Graphviz needed) and write it as SVG atomically."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        layer = self.layers()
        columns: dict[int, list[str]] = {}
        for v in sorted(layer, key=lambda v: (layer[v], v)):
            columns.setdefault(layer[v], []).append(v)
        pos = {v: (c * 3.0, -r * 0.8) for c, vs in columns.items() for r, v in enumerate(vs)}
        height = max((len(v) for v in columns.values()), default=1)
        fig, ax = plt.subplots(figsize=(3 + 3 * len(columns), 1 + 0.6 * height))
        boxes = {}
        for v, (x, y) in pos.items():
            is_topic = v in self.topics
            boxes[v] = ax.text(
                x, y, v, ha="center", va="center", fontsize=8, zorder=2,
                bbox={"boxstyle": "square" if is_topic else "round", "fc": "#e8f0ff" if is_topic else "#fff2cc"},
            )  # fmt: skip
        for t, (pubs, subs) in self.topics.items():
            for a, b in [*((p, t) for p in pubs), *((t, s) for s in subs)]:
                forward = pos[b][0] >= pos[a][0]  # arrows leave the right edge and enter the left edge
                ax.annotate(
                    "", xy=(0.0 if forward else 1.0, 0.5), xycoords=boxes[b],
                    xytext=(1.0 if forward else 0.0, 0.5), textcoords=boxes[a],
                    arrowprops={"arrowstyle": "-|>", "color": "0.35", "shrinkA": 3, "shrinkB": 3}, zorder=1,
                )  # fmt: skip
        ax.set_axis_off()
        xs = [p[0] for p in pos.values()] or [0.0]
        ys = [p[1] for p in pos.values()] or [0.0]
        ax.set_xlim(min(xs) - 1.5, max(xs) + 1.5)
        ax.set_ylim(min(ys) - 0.6, max(ys) + 0.6)
        save_figure_atomic(fig, path, bbox_inches="tight")
        plt.close(fig)
