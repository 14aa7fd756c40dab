"""Opaque XML fragments: elements mpc does not model, carried along unchanged.

`<gazebo>`, `<transmission>`, `<ros2_control>`, vendor tags and unknown children of
links and joints travel as serialised XML. A fragment records where it refers to a
link or joint by name, so that a rename or a cut can keep it right instead of
dropping it.
"""

from __future__ import annotations

from typing import Any, Literal, Protocol

from mpc.core.record import lazy_twin, record
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


@record(slots=True, kw_only=True)
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


class RefFinder(Protocol):
    """What finds a lazy fragment's references (backends/urdf_fragments.py: Fragments)."""

    def refs(self, node: Any, /) -> tuple[FragmentRef, ...]: ...


@lazy_twin(Fragment)
class LazyFragment(Fragment):
    """A Fragment whose `refs` are found when first asked for (`lazy_fragment`).

    A URDF reader meets a hundred fragments (TALOS: 138 `<gazebo>` and `<transmission>`), and
    walking each for the link and joint names it mentions was a twelfth of the read; only a
    rename or a cut asks for them. Until then it holds its element (and with it the parsed
    file, as a LazySpan does); afterwards it is a Fragment in all but its class. It pickles,
    copies, compares and is kept as the Fragment it is (asking for every field).

    The text is found by the reader, not here: serialised while the reader is at the element,
    it took half the time it took when a write asked for it (the parsed tree out of the
    processor's caches by then).
    """

    __slots__ = ("_finder", "_node")
    _finder: RefFinder | None
    _node: Any

    def __getattr__(self, name: str) -> Any:  # only for a slot not set yet: refs
        finder = object.__getattribute__(self, "_finder") if name == "refs" else None
        if finder is None:
            raise AttributeError(name)
        refs = finder.refs(object.__getattribute__(self, "_node"))
        _set_refs(self, refs)
        _set_finder(self, None)  # lets the parsed file go
        _set_node(self, None)
        return refs


_set_tag, _set_xml, _set_refs, _set_comments, _set_span = (
    Fragment.__dict__[name].__set__ for name in ("tag", "xml", "refs", "comments", "span"))
_set_finder, _set_node = (LazyFragment.__dict__[name].__set__ for name in ("_finder", "_node"))
_new = object.__new__


def lazy_fragment(tag: str, xml: str, comments: tuple[str, ...], span: Span | None,
                  finder: RefFinder, node: Any) -> Fragment:
    """The Fragment of `node`, whose `refs` `finder` gives when first asked for (LazyFragment)."""
    fragment = _new(LazyFragment)
    _set_tag(fragment, tag)
    _set_xml(fragment, xml)
    _set_comments(fragment, comments)
    _set_span(fragment, span)
    _set_finder(fragment, finder)
    _set_node(fragment, node)
    return fragment
