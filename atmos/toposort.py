"""Stable topological sort shared by the system schedule and the render graph."""
from __future__ import annotations

import heapq
from typing import Hashable, Iterable


class CycleError(ValueError):
    """The ordering constraints form a cycle; ``cycle`` lists the nodes on it."""

    def __init__(self, cycle: list):
        self.cycle = cycle
        super().__init__(" -> ".join(map(str, cycle + cycle[:1])))


def stable_toposort(nodes: list[Hashable], edges: Iterable[tuple[Hashable, Hashable]]) -> list:
    """Order ``nodes`` so that every edge (a, b) puts a before b; ties keep the order of ``nodes``."""
    rank = {node: i for i, node in enumerate(nodes)}
    succ: dict = {node: set() for node in nodes}
    indeg = dict.fromkeys(nodes, 0)
    for a, b in edges:
        if b not in succ[a]:
            succ[a].add(b)
            indeg[b] += 1
    ready = [rank[n] for n in nodes if indeg[n] == 0]
    heapq.heapify(ready)
    order = []
    while ready:
        node = nodes[heapq.heappop(ready)]
        order.append(node)
        for nxt in succ[node]:
            indeg[nxt] -= 1
            if indeg[nxt] == 0:
                heapq.heappush(ready, rank[nxt])
    if len(order) < len(nodes):
        raise CycleError(_find_cycle([n for n in nodes if indeg[n] > 0], succ))
    return order


def _find_cycle(left: list, succ: dict) -> list:
    """One cycle among the nodes a topological sort could not place."""
    remaining = set(left)
    node, seen = left[0], []
    while node not in seen:
        seen.append(node)
        node = next(n for n in sorted(succ[node], key=left.index) if n in remaining)
    return seen[seen.index(node):]
