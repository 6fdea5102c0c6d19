"""What the first Apply's node group costs in Blender: its build, the bpy calls it makes and
what one such call costs (a benchmark, not a test).

    python bench/group_build.py --repo CHECKOUT [--case defaults/principled] [--repeats 10]
                                [--json FILE]

In one process: the case's first Apply at preview first (the scene of bench/interactive.py),
the arguments of its group's build (``nodes.build_group``) kept; then that build repeated into
new groups, in CPU seconds (``time.process_time``), the best and the median of ``--repeats``;
as many times again with its bpy calls counted and timed by kind (``nodes.new``, a node's
setting, a socket's value, ``links.new``), in the fastest of those, the rest being the group's
interface, its image and record, the Python side (the tier's formulas, socket lookups) and
the timing's own clock reads (about a microsecond each, two a call); and each kind
alone on a copy of the group's largest tree (the group's own, or its largest part: every
change made through Python runs Blender's node-tree update, ``BKE_main_ensure_invariants``,
over the whole tree, in parallel above 32 nodes).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections import Counter
from pathlib import Path

from checkout import addon_attribute, machine_load, write_figures  # bench/checkout.py
from interactive import _scene, _setup  # bench/interactive.py

KINDS = ("nodes.new", "setting", "value", "links.new")
_clock = time.process_time


class _Timed:
    """A tree's ``nodes`` or ``links`` whose ``new`` is timed into ``spent[kind]``."""

    def __init__(self, collection, kind: str, spent: Counter, counts: Counter):
        self._collection, self._kind, self._spent, self._counts = collection, kind, spent, counts

    def new(self, *args):
        start = _clock()
        out = self._collection.new(*args)
        self._spent[self._kind] += _clock() - start
        self._counts[self._kind] += 1
        return out

    def __len__(self):
        return len(self._collection)

    def __getattr__(self, name):
        return getattr(self._collection, name)


def _timed_build(modules, args: tuple, kwargs: dict, group) -> tuple[float, Counter, Counter]:
    """One build into ``group`` with its bpy calls timed by kind: ``(CPU s, spent, counts)``."""
    nodes, algebra = modules
    spent, counts = Counter(), Counter()
    plain_set, plain_feed, plain_builder = algebra._set, algebra.Builder.feed, nodes.Builder

    class Builder(plain_builder):
        """The checkout's Builder, its node additions and links timed (in whichever tree
        they go: the group's or, built as parts, a part's; a checkout from before parts links
        through the tree's own collections, timed by :class:`_Timed`)."""

        def __init__(self, tree, **options):
            super().__init__(tree, **options)
            if not hasattr(plain_builder, "_connect"):
                self.tree = type("Tree", (), {
                    "nodes": _Timed(tree.nodes, "nodes.new", spent, counts),
                    "links": _Timed(tree.links, "links.new", spent, counts)})()

        def node(self, kind, label="", **props):
            if not hasattr(plain_builder, "_connect"):
                return super().node(kind, label, **props)
            start, setting = _clock(), spent["setting"]
            out = super().node(kind, label, **props)
            spent["nodes.new"] += _clock() - start - (spent["setting"] - setting)
            counts["nodes.new"] += 1
            return out

        def _connect(self, source, target):
            start = _clock()
            super()._connect(source, target)
            spent["links.new"] += _clock() - start
            counts["links.new"] += 1

    def timed_set(node, props):
        counts["setting"] += sum(getattr(node, name) != value for name, value in props.items())
        start = _clock()
        plain_set(node, props)
        spent["setting"] += _clock() - start

    def timed_feed(self, target, value):
        start, linked = _clock(), spent["links.new"]
        plain_feed(self, target, value)
        if spent["links.new"] == linked:
            spent["value"] += _clock() - start
            counts["value"] += 1

    algebra._set, algebra.Builder.feed, nodes.Builder = timed_set, timed_feed, Builder
    try:
        start = _clock()
        nodes.build_group(*args, group, **kwargs)
        return _clock() - start, spent, counts
    finally:
        algebra._set, algebra.Builder.feed, nodes.Builder = plain_set, plain_feed, plain_builder


def _alone(bpy, group, repeats: int = 20) -> dict:
    """Microseconds of CPU per call of each kind, on a copy of ``group`` (its size)."""
    tree = group.copy()
    clock = time.process_time
    start = clock()
    added = [tree.nodes.new("ShaderNodeMath") for _ in range(repeats)]
    new = clock() - start
    start = clock()
    for node in added:
        node.operation = "MULTIPLY"
    setting = clock() - start
    start = clock()
    for node in added:
        node.inputs[1].default_value = 0.25
    value = clock() - start
    start = clock()
    for a, b in zip(added, added[1:], strict=False):
        tree.links.new(a.outputs[0], b.inputs[0])
    link = clock() - start
    bpy.data.node_groups.remove(tree)
    return {kind: round(1e6 * seconds / count, 1) for kind, seconds, count in (
        ("nodes.new", new, repeats), ("setting", setting, repeats), ("value", value, repeats),
        ("links.new", link, repeats - 1))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", type=Path, default=Path(__file__).resolve().parents[1])
    parser.add_argument("--case", default="defaults/principled")
    parser.add_argument("--repeats", type=int, default=10)
    parser.add_argument("--json", type=Path)
    options = parser.parse_args()
    load = machine_load()
    bpy, *support = _setup(options.repo.resolve())
    apply_to_object = addon_attribute("apply_to_object")
    package = apply_to_object.__module__.rsplit(".", 1)[0]
    modules = (sys.modules[f"{package}.nodes"], sys.modules[f"{package}.node_algebra"])
    nodes = modules[0]
    caught: list = []
    plain = nodes.build_group
    nodes.build_group = lambda *a, **k: caught.append((a[:3], k)) or plain(*a, **k)
    with support[1].addon_registered():
        obj = _scene(bpy, *support, options.case)
        apply_to_object(bpy.context, obj, preview_first=True)
        nodes.build_group = plain
        args, kwargs = caught[0]
        seconds = []
        for _ in range(options.repeats):
            group = bpy.data.node_groups.new("timed", "ShaderNodeTree")
            start = time.process_time()
            nodes.build_group(*args, group, **kwargs)
            seconds.append(time.process_time() - start)
        timed = []
        for _ in range(options.repeats):
            group = bpy.data.node_groups.new("by kind", "ShaderNodeTree")
            timed.append(_timed_build(modules, args, kwargs, group))
        total, spent, counts = min(timed, key=lambda run: run[0])
        # The checkout's parts (none before the add-on built groups as parts).
        parts = sys.modules.get(f"{package}.group_parts")
        trees = [group, *(parts.parts_of(group) if parts is not None else ())]
        results = {
            "case": options.case, "nodes": sum(len(tree.nodes) for tree in trees),
            "links": sum(len(tree.links) for tree in trees), "trees": len(trees),
            "build_cpu_s": {"best": min(seconds), "median": statistics.median(seconds)},
            "by_kind": {kind: {"calls": counts[kind], "cpu_s": spent[kind]} for kind in KINDS},
            "rest_cpu_s": total - sum(spent.values()),
            "timed_build_cpu_s": total,
            "alone_us_per_call": _alone(bpy, max(trees, key=lambda tree: len(tree.nodes))),
            "load": [load, machine_load()]}
    print(f"{options.case}: {results['nodes']} nodes, {results['links']} links in "
          f"{results['trees']} tree(s); build "
          f"{1e3 * min(seconds):.1f} ms best, {1e3 * statistics.median(seconds):.1f} median")
    for kind in KINDS:
        print(f"  {kind:10s} {counts[kind]:4d} calls {1e3 * spent[kind]:6.2f} ms "
              f"(alone on its largest tree: {results['alone_us_per_call'][kind]} us each)")
    print(f"  the rest {1e3 * results['rest_cpu_s']:.2f} ms of {1e3 * total:.1f} (interface, "
          f"image, Python, clock reads); "
          f"load {results['load']}")
    write_figures(options.json, results)


if __name__ == "__main__":
    main()
