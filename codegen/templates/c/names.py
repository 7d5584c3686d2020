"""Every identifier the C templates generate, derived with the view model's own attributes.

`identifiers(spec, vm)` lists what the templates print from the spec; the names the
templates spell out themselves are read from their text (template_names). The test
tests/hostile/test_spec_identifiers.py tokenises the generated C and fails on any
name that is neither, so the two cannot drift apart.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Iterator

from codegen import names as N
from codegen.model import ERROR_KINDS, Spec

from . import view

# C99 and C11 keywords (C11's are reserved spellings anyway), plus C23's new ones.
KEYWORDS = frozenset("""
auto break case char const continue default do double else enum extern float for goto if inline int long
register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while
_Alignas _Alignof _Atomic _Bool _Complex _Generic _Imaginary _Noreturn _Static_assert _Thread_local
alignas alignof bool constexpr false nullptr static_assert thread_local true typeof typeof_unqual
""".split())

# Names the generated code sees from its headers (stdint.h, stddef.h, string.h, avr/pgmspace.h) or the
# compiler predefines in GNU modes; as a member or function name they would be replaced or clash.
STANDARD = frozenset("""
NULL EOF offsetof size_t ptrdiff_t wchar_t max_align_t errno assert memcpy memmove memset memcmp strcmp strncmp
strcpy strncpy strlen strcat strchr strrchr strstr strtok memchr strerror strcoll strxfrm strspn strcspn strpbrk
int8_t int16_t int32_t int64_t uint8_t uint16_t uint32_t uint64_t intptr_t uintptr_t intmax_t uintmax_t
int_least8_t int_least16_t int_least32_t int_least64_t uint_least8_t uint_least16_t uint_least32_t uint_least64_t
int_fast8_t int_fast16_t int_fast32_t int_fast64_t uint_fast8_t uint_fast16_t uint_fast32_t uint_fast64_t
linux unix i386 i686 x86_64 amd64 arm avr mips sparc sun vax complex imaginary noreturn
PROGMEM pgm_read_byte pgm_read_word pgm_read_dword main
""".split())
_STDINT_MACRO = re.compile(r"^U?INT(_LEAST|_FAST|PTR|MAX)?[0-9]*_(MAX|MIN|C)$|^(SIZE|PTRDIFF|WCHAR|WINT|SIG_ATOMIC)_(MAX|MIN)$")
_C_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")

TEMPLATES = Path(__file__).resolve().parent


def template_names() -> frozenset[str]:
    """Every identifier the C templates spell out themselves (macros, functions, types, enum constants,
    locals), read from their text outside Jinja tags and C comments, so this follows the templates."""
    names: set[str] = set()
    for path in sorted(TEMPLATES.glob("*.j2")):
        text = re.sub(r"{{.*?}}|{%.*?%}|{#.*?#}", " ", path.read_text(encoding="utf-8"), flags=re.S)
        text = re.sub(r"/\*.*?\*/|//[^\n]*", " ", text, flags=re.S)
        names |= {t for t in re.findall(r"[A-Za-z_]\w*|\d\w*", text) if not t[0].isdigit()}
    return frozenset(names - KEYWORDS)


# plus what the templates build from lists of their own: the error kinds and arachnae_generic.h.j2's field kinds
FIXED = (template_names() | {f"ARACHNAE_{kind}" for kind, _doc in ERROR_KINDS}
         | {f"ARACHNAE_KIND_{kind}" for kind in ("UINT", "INT", "ENUM", "FLAGS", "NODE", "CHAR")})


def rules() -> N.Rules:
    return N.Rules("C", lambda s: bool(_C_IDENT.match(s)), reserved)


def reserved(name: str) -> str | None:
    """Why `name` may not be generated from the spec (None: it may)."""
    if name in KEYWORDS:
        return "a C keyword"
    if name.startswith("__") or re.match(r"^_[A-Z]", name):
        return "reserved for the C implementation"
    if name in STANDARD or _STDINT_MACRO.match(name):
        return "a name of the C library or a predefined macro"
    return None


SCOPE = "the C file scope"   # macros, functions, types and statics of every generated file together


def identifiers(spec: Spec, vm: dict) -> Iterator[N.Ident]:
    """Every identifier and file name the C templates print, with the spec item it comes from."""
    for name in sorted(FIXED):
        yield N.Ident(SCOPE, name, None)
    yield N.Ident("the C union arachnae_message.u", "none", None)
    for t in vm["tables"]:
        for suffix in ("_to_milli", "_to_raw"):
            yield N.Ident(SCOPE, t.prefix + suffix, None)
        yield N.Ident("the generated C files", t.file, None, is_file=True)
    for name in ("arachnae.h", "arachnae_frame.c", "arachnae_generic.h", "arachnae_generic.c"):
        yield N.Ident("the generated C files", name, None, is_file=True)
    for n in spec.nodes:
        yield N.Ident(SCOPE, f"ARACHNAE_ADDR_{n.ident}", N.of_node(spec, n))
    for rv in vm["roles"]:
        at = N.of_role(spec, rv.role)
        yield N.Ident(SCOPE, f"ARACHNAE_RX_MAX_{rv.role.upper()}", at)
        yield N.Ident(SCOPE, rv.guard, at)
        yield N.Ident(SCOPE, rv.node_t, at)
        hooks = ["node_init", "payload_check", "dispatch", "send"]
        hooks += ["on_init"] if rv.init else []
        hooks += ["on_status_req"] if rv.status_req else []
        for hook in hooks:
            yield N.Ident(SCOPE, f"{rv.lname}_{hook}", at)
        for mv in rv.others:
            yield N.Ident(SCOPE, f"{rv.lname}_on_{mv.lname}", N.of_message(spec, mv.m))
        for mv in rv.field_others:
            yield N.Ident(f"the C union {rv.node_t}.msg", f"rx_{mv.lname}", N.of_message(spec, mv.m))
        for mv in rv.others:
            if mv.name in rv.replies:
                yield N.Ident(f"the C union {rv.node_t}.msg", f"reply_{mv.lname}", N.of_message(spec, mv.m))
        # the role's own byte parser (parser.j2)
        yield N.Ident(SCOPE, rv.rx_init, at)
        for suffix in ("rx", "rx_feed", "rx_gap", "rx_frame"):
            yield N.Ident(SCOPE, f"{rv.lname}_{suffix}", at)
        for suffix in (".h", ".c"):
            yield N.Ident("the generated C files", f"node_{rv.lname}{suffix}", at, is_file=True)
    for mv in vm["messages"]:
        at = N.of_message(spec, mv.m)
        yield N.Ident(SCOPE, mv.op_macro, at)
        for suffix in ("MIN_SIZE", "MAX_SIZE", "FRAME_MAX"):
            yield N.Ident(SCOPE, f"ARACHNAE_{mv.name}_{suffix}", at)
        functions = ["validate", "build"] + (["decode", "check", "encode", "unpack", "pack"] if mv.has_fields else [])
        for fn in functions:
            yield N.Ident(SCOPE, f"{mv.prefix}_{fn}", at)
        yield N.Ident("the generated C files", mv.file, at, is_file=True)
        if not mv.has_fields:
            continue
        yield N.Ident(SCOPE, mv.type, at)
        yield N.Ident(SCOPE, f"FIELDS_{mv.name}", at)
        yield N.Ident("the C union arachnae_message.u", mv.lname, at)
        for fv in mv.fields:
            fat = N.of_field(spec, mv.m, fv.f)
            yield N.Ident(f"the C struct {mv.type}", fv.name, fat)
            if fv.scaled is not None:
                for fn in (fv.scaled.to_milli, fv.scaled.from_milli):
                    yield N.Ident(SCOPE, fn, fat)
                    yield N.Ident(SCOPE, f"w_{fn}", fat)
    for name, e in vm["enums"].items():
        for key in e.values:
            yield N.Ident(SCOPE, f"ARACHNAE_{name}_{key}", N.of_enum(e, key))
    for name, fl in vm["flags"].items():
        for key in fl.bits:
            yield N.Ident(SCOPE, f"ARACHNAE_{name}_{key}", N.of_enum(fl, key))
        yield N.Ident(SCOPE, f"ARACHNAE_{name}_MASK", N.of_enum(fl))


def check(spec: Spec) -> list[N.Problem]:
    """What the C target cannot generate from `spec`, at the spec item responsible."""
    try:
        vm = view(spec)
    except N.Unsupported as exc:
        return [N.Problem(exc.origin, exc.message)]
    return N.check_identifiers(identifiers(spec, vm), rules())
