"""Opaque XML fragments: elements mpc does not model, carried along unchanged.

`<gazebo>`, `<transmission>`, `<ros2_control>`, vendor tags and unknown children of
links and joints travel as serialised XML. A fragment records where it refers to a
link or joint by name, so that a rename or a cut can keep it right instead of
dropping it.
"""

from __future__ import annotations

from typing import Literal

from mpc.core.record import record
from mpc.core.span import Span

RefKind = Literal["link", "joint"]


@record(slots=True, bulk=True)
class FragmentRef:
    """One place in a fragment that names a link or joint.

    path: child indices from the fragment's root element to the element holding the name.
    attr: the attribute holding the name, or None for the element's text.
    kind: whether the name is a link's or a joint's.
    name: the name found there.
    """

    path: tuple[int, ...]
    attr: str | None
    kind: RefKind
    name: str


@record(slots=True, kw_only=True, bulk=True)
class Fragment:
    """An XML element kept verbatim.

    tag: the element's tag, for messages and ordering.
    xml: the element serialised (comments inside it included).
    refs: the link and joint names it refers to, and where.
    comments: comments that stood right before it in the source.
    span: where it was read from.
    """

    tag: str
    xml: str
    refs: tuple[FragmentRef, ...] = ()
    comments: tuple[str, ...] = ()
    span: Span | None = None

    def names(self, kind: RefKind) -> frozenset[str]:
        """The link (or joint) names this fragment refers to."""
        return frozenset(r.name for r in self.refs if r.kind == kind)
