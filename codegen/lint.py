"""Checks that the spec is well-formed and means something consistent.

Structure is checked with JSON Schema (codegen/schema/); meaning here: unique
addresses and opcodes, widths that hold their ranges, references that resolve,
and routes that stay on one bus. All problems are collected and reported
together as `file:line: message`, one per line.
"""
from __future__ import annotations

import importlib
import importlib.util
from fractions import Fraction
from pathlib import Path
from typing import Any

from arachnae.errors import UserError, located
from arachnae.validation import field_name, schema_errors
from codegen.encoding import Linear, Log10, to_fraction
from codegen.generate import LANGUAGES
from codegen.model import Checksum, Spec, enum_values_of
from arachnae.yamlio import line_of, load_yaml

SCHEMA_DIR = Path(__file__).resolve().parent / "schema"


class Report:
    """Collects diagnostics for several files."""

    def __init__(self) -> None:
        self.problems: list[str] = []

    def add(self, path: Path, doc: Any, where: list[Any], message: str) -> None:
        self.problems.append(located(str(path), line_of(doc, where), one_line(message)))

    def raise_if_any(self) -> None:
        if self.problems:
            raise UserError("\n".join(self.problems))


def one_line(text: str) -> str:
    """A diagnostic stays one line whatever the spec's strings contain."""
    return "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in text)


def _lint_text(path: Path, doc: Any, node: Any, where: list[Any], report: Report) -> None:
    """Strings must be text: a lone surrogate (YAML "\\ud800") cannot be written to any generated file."""
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        for text in (key, value):
            if isinstance(text, str) and any(0xD800 <= ord(ch) <= 0xDFFF for ch in text):
                report.add(path, doc, where + [key], f"{field_name(where + [key])}: {text!r} contains a lone surrogate, not text")
        _lint_text(path, doc, value, where + [key], report)


def _schema_check(path: Path, doc: Any, schema_name: str, report: Report) -> None:
    """Structure, worded as every other schema check of the toolkit (arachnae.validation: `file:line: field: problem`)."""
    report.problems += [one_line(str(e)) for e in schema_errors(doc, load_yaml(SCHEMA_DIR / schema_name))]


def check_documents(nodes_path: Path, messages_path: Path) -> tuple[dict, dict]:
    """Load both spec files and return them if they are valid; else raise UserError with every problem."""
    report = Report()
    nodes_doc = load_yaml(nodes_path)
    messages_doc = load_yaml(messages_path)
    for path, doc in ((nodes_path, nodes_doc), (messages_path, messages_doc)):
        _lint_text(path, doc, doc, [], report)
    _schema_check(nodes_path, nodes_doc, "nodes.schema.yaml", report)
    _schema_check(messages_path, messages_doc, "messages.schema.yaml", report)
    report.raise_if_any()
    roles = _lint_nodes(nodes_path, nodes_doc, report)
    nodes_ok = not report.problems  # routes over a broken node table would only repeat its problems
    _lint_messages(messages_path, messages_doc, nodes_doc, roles, report, check_routes=nodes_ok)
    _lint_request_messages(nodes_path, nodes_doc, messages_doc, report)
    _lint_reflexes(nodes_path, nodes_doc, messages_doc, report)
    report.raise_if_any()
    return nodes_doc, messages_doc


def check_targets(spec: Spec, paths: tuple[Path, Path], docs: tuple[dict, dict]) -> None:
    """Refuse a spec that some target cannot turn into code that compiles and imports (issue 10).

    Each target folder's `names.check` builds that target's view model and lists
    what it cannot express and every generated identifier that is invalid,
    reserved, or shared by two spec items after mangling.
    """
    report = Report()
    where = {"nodes": (paths[0], docs[0]), "messages": (paths[1], docs[1])}
    for lang in LANGUAGES:
        module = f"codegen.templates.{lang}.names"
        if importlib.util.find_spec(module) is None:
            continue
        for problem in importlib.import_module(module).check(spec):
            path, doc = where[problem.origin.file]
            report.add(path, doc, list(problem.origin.path), f"{problem.origin.what}: {problem.message}")
    report.problems = list(dict.fromkeys(report.problems))
    report.raise_if_any()


# -- nodes ----------------------------------------------------------------------
def _lint_nodes(path: Path, doc: dict, report: Report) -> set[str]:
    broadcast = doc["address"]["broadcast"]
    level_shift = doc["address"]["width_bits"] - doc["address"]["level_bits"]
    buses = doc["buses"]
    seen_addr: dict[int, str] = {}
    seen_short: set[str] = set()
    shorts = {n["short"] for n in doc["nodes"]}
    mastered: dict[str, str] = {}
    for i, n in enumerate(doc["nodes"]):
        at = ["nodes", i]
        addr, short = n["address"], n["short"]
        if addr == broadcast:
            report.add(path, doc, at, f"{short}: address 0x{addr:02X} is the broadcast address (seed 3.2.1)")
        elif addr in seen_addr:
            report.add(path, doc, at, f"{short}: duplicate address 0x{addr:02X}, already used by {seen_addr[addr]}")
        seen_addr.setdefault(addr, short)
        if short in seen_short:
            report.add(path, doc, at, f"duplicate node name {short}")
        seen_short.add(short)
        if addr >> level_shift != n["level"]:
            report.add(path, doc, at, f"{short}: level {n['level']} does not match address 0x{addr:02X} (top bits say {addr >> level_shift})")
        if n["bus"] is not None and n["bus"] not in buses:
            report.add(path, doc, at, f"{short}: unknown bus '{n['bus']}'")
        if "masters" in n:
            if n["masters"] not in buses:
                report.add(path, doc, at, f"{short}: masters unknown bus '{n['masters']}'")
            elif buses[n["masters"]]["master"] != short:
                report.add(path, doc, at, f"{short}: masters '{n['masters']}' but that bus names {buses[n['masters']]['master']} as master")
            mastered[n["masters"]] = short
    for name, b in buses.items():
        at = ["buses", name]
        if b["master"] not in shorts:
            report.add(path, doc, at, f"bus {name}: unknown master node '{b['master']}'")
        elif name not in mastered:
            report.add(path, doc, at, f"bus {name}: its master {b['master']} does not declare `masters: {name}`")
        if b["arbitration"] not in doc["arbitration"]:
            report.add(path, doc, at, f"bus {name}: unknown arbitration rule '{b['arbitration']}'")
    for name, line in doc.get("lines", {}).items():
        if line["node"] not in shorts:
            report.add(path, doc, ["lines", name, "node"], f"line {name}: unknown node '{line['node']}'")
    roles = {n["role"] for n in doc["nodes"]}
    for i, q in enumerate(doc["post"]["quorums"]):
        for role in q["unit_roles"]:
            if role not in roles:
                report.add(path, doc, ["post", "quorums", i], f"quorum {q['name']}: unknown role '{role}'")
        units = {n.get(q["unit_key"]) for n in doc["nodes"] if n["role"] in q["unit_roles"]} - {None}
        if q["min_complete"] > len(units):
            report.add(path, doc, ["post", "quorums", i, "min_complete"], f"quorum {q['name']}: needs {q['min_complete']} units but only {len(units)} exist")
    return roles


def _lint_request_messages(path: Path, doc: dict, messages_doc: dict, report: Report) -> None:
    """A bus's request message must exist and be sent by its slaves to its master (seed 3.2.2)."""
    by_name = {m["name"]: m for m in messages_doc["messages"]}
    master_role = {n["short"]: n["role"] for n in doc["nodes"]}
    for bus, b in doc["buses"].items():
        name = b.get("request_message")
        if name is None:
            if "fetch_message" in b:
                report.add(path, doc, ["buses", bus, "fetch_message"], f"bus {bus}: fetch_message without a request_message")
            continue
        m = by_name.get(name)
        if m is None:
            report.add(path, doc, ["buses", bus, "request_message"], f"bus {bus}: request_message unknown message '{name}'")
            continue
        slave_roles = {n["role"] for n in doc["nodes"] if n["bus"] == bus}
        if master_role.get(b["master"]) not in m["to"] or not slave_roles & set(m["from"]):
            report.add(path, doc, ["buses", bus, "request_message"], f"bus {bus}: {name} is not sent by its slaves to {b['master']}")
            continue
        senders = {n["short"] for n in doc["nodes"] if n["bus"] == bus and n["role"] in m["from"]}
        for i, short in enumerate(b.get("priority", [])):
            if short not in senders:
                report.add(path, doc, ["buses", bus, "priority", i], f"bus {bus}: priority names {short}, which does not send {name} on it")
        _lint_fetch(path, doc, bus, b, master_role[b["master"]], slave_roles & set(m["from"]), by_name, report)


def _lint_fetch(path: Path, doc: dict, bus: str, b: dict, master: str, requesters: set[str], by_name: dict,
                report: Report) -> None:
    """seed 3.2.2: the master fetches the record of the request it serves with the bus's fetch_message, and each
    requesting role has a record (`record: true`) for the master: the models and the trace checker rely on both."""
    at = ["buses", bus, "fetch_message"]
    fetch = by_name.get(b.get("fetch_message", ""))
    if "fetch_message" not in b:
        report.add(path, doc, ["buses", bus], f"bus {bus}: a bus with a request_message needs a fetch_message")
    elif fetch is None:
        report.add(path, doc, at, f"bus {bus}: fetch_message unknown message '{b['fetch_message']}'")
    elif master not in fetch["from"] or not requesters <= set(fetch["to"]):
        report.add(path, doc, at, f"bus {bus}: {fetch['name']} is not sent by {b['master']} to every role that requests the line")
    for role in sorted(requesters):
        if not any(m.get("record") and role in m["from"] and master in m["to"] for m in by_name.values()):
            report.add(path, doc, ["buses", bus, "request_message"],
                       f"bus {bus}: {role} requests the line but sends {b['master']} no message with `record: true`")


def _lint_reflexes(path: Path, doc: dict, messages_doc: dict, report: Report) -> None:
    """A reflex's source, actor and target are nodes; the actor sends the message to the target (seed 5.2)."""
    by_short = {n["short"]: n for n in doc["nodes"]}
    by_name = {m["name"]: m for m in messages_doc["messages"]}
    enum_values = {k: set(enum_values_of(messages_doc, k)) for k in messages_doc["enums"]}
    for i, r in enumerate(doc.get("reflexes", [])):
        at = ["reflexes", i]
        missing = [k for k in ("source", "actor", "to") if r[k] not in by_short]
        if missing:
            report.add(path, doc, at, f"reflex {r['name']}: unknown node(s) {', '.join(r[k] for k in missing)}")
            continue
        m = by_name.get(r["message"])
        if m is None or by_short[r["actor"]]["role"] not in m["from"] or by_short[r["to"]]["role"] not in m["to"]:
            report.add(path, doc, at + ["message"], f"reflex {r['name']}: {r['actor']} does not send {r['message']} to {r['to']}")
            continue
        if not any(r["command"] in vals for vals in enum_values.values()):
            report.add(path, doc, at + ["command"], f"reflex {r['name']}: command {r['command']} is no enum value")


# -- messages -------------------------------------------------------------------
def _lint_carried(path: Path, doc: dict, i: int, m: dict, report: Report) -> None:
    """A message `carried_in` another travels as a code of one of its fields: the carrier goes between the same
    roles and has a flags bit or enum value of the message's name (seed 3.2.12: OBJ_LEFT in XMIT_DATA_TPSC)."""
    at = ["messages", i, "carried_in"]
    carrier = next((c for c in doc["messages"] if c["name"] == m["carried_in"]), None)
    if carrier is None or carrier is m:
        report.add(path, doc, at, f"{m['name']}: carried_in unknown message '{m['carried_in']}'")
        return
    if (set(carrier["from"]), set(carrier["to"])) != (set(m["from"]), set(m["to"])):
        report.add(path, doc, at, f"{m['name']}: carried_in {carrier['name']}, which goes between other roles")
    codes = [f.get("flags") or f.get("enum") for f in carrier.get("fields", [])]
    named = [c for c in codes if c and m["name"] in ((doc.get("flags", {}).get(c) or {}).get("bits", {})
                                                     or (doc.get("enums", {}).get(c) or {}).get("values", {}))]
    if not named:
        report.add(path, doc, at, f"{m['name']}: {carrier['name']} has no flags bit or enum value named {m['name']} to carry it")


def _lint_reply(path: Path, doc: dict, i: int, m: dict, report: Report) -> None:
    """seed 3.2.2: a reply goes back from a receiver of its request to a sender of it, and a role answers a
    request with one message only (which one the skeletons send)."""
    at = ["messages", i, "reply_to"]
    request = next((r for r in doc["messages"] if r["name"] == m["reply_to"]), None)
    if request is None:
        report.add(path, doc, at, f"{m['name']}: reply_to unknown message '{m['reply_to']}'")
        return
    for side, other, says in (("from", "to", "receive"), ("to", "from", "send")):
        stray = [r for r in m[side] if r not in request[other]]
        if stray:
            report.add(path, doc, at, f"{m['name']}: {', '.join(stray)} do(es) not {says} {request['name']}, "
                                      f"so cannot be on the `{side}` side of its reply")
    for other in doc["messages"][:i]:
        both = [r for r in m["from"] if other.get("reply_to") == m["reply_to"] and r in other["from"]]
        if both:
            report.add(path, doc, at, f"{m['name']}: {', '.join(both)} already answer(s) {m['reply_to']} with {other['name']}")


_ENCODING_KEYS = ("type", "bits", "unit", "scale", "offset", "log10", "range", "enum", "flags")


def _encoding(f: dict) -> dict:
    """What decides a field's raw value and its meaning: two fields with equal encodings read alike."""
    return {k: str(f.get(k, 8 if k == "bits" else None)) for k in _ENCODING_KEYS}


def _lint_record_values(path: Path, doc: dict, i: int, m: dict, report: Report) -> None:
    """seed 3.2.2, 6.2: a sensor record's `record_values` are fields of it, one encoding, each fits the XMIT_RECORD's
    one value byte; `record_channel` is another integer field, for a record of one value."""
    at, name = ["messages", i], m["name"]
    fields = {f["name"]: f for f in m.get("fields", [])}
    if "record_channel" in m and "record_values" not in m:
        report.add(path, doc, at + ["record_channel"], f"{name}: record_channel needs record_values")
    if "record_values" not in m:
        return
    if not m.get("record"):
        report.add(path, doc, at + ["record_values"], f"{name}: record_values is for records (`record: true`)")
    if len(m["from"]) != 1:
        report.add(path, doc, at + ["record_values"], f"{name}: record_values belongs to one role's data, not {'/'.join(m['from'])}")
    values = [fields.get(v) for v in m["record_values"]]
    for j, (v, f) in enumerate(zip(m["record_values"], values)):
        if f is None:
            report.add(path, doc, at + ["record_values", j], f"{name}: record_values names '{v}', which is no field of it")
        elif f["type"] not in ("uint", "int", "flags", "enum") or "count" in f or f.get("bits", 8) > 8:
            report.add(path, doc, at + ["record_values", j], f"{name}.{v}: a record carries one value byte, "
                                                            f"not a {f.get('bits', 8)}-bit {f['type']}{' array' if 'count' in f else ''}")
        elif _encoding(f) != _encoding(values[0] or f):
            report.add(path, doc, at + ["record_values", j], f"{name}.{v}: encoded unlike {m['record_values'][0]}; "
                                                            f"a record's values share one encoding")
    channel = m.get("record_channel")
    if channel is None:
        return
    f = fields.get(channel)
    if f is None or f["type"] not in ("uint", "enum") or "count" in f:
        report.add(path, doc, at + ["record_channel"], f"{name}: record_channel '{channel}' is no unsigned integer field of it")
    elif channel in m["record_values"]:
        report.add(path, doc, at + ["record_channel"], f"{name}: record_channel '{channel}' is one of its record_values")
    elif len(m["record_values"]) != 1:
        report.add(path, doc, at + ["record_channel"], f"{name}: record_channel gives the channel of one value, "
                                                      f"not of {len(m['record_values'])}")


def _lint_compared(path: Path, doc: dict, i: int, m: dict, report: Report) -> None:
    """seed 3.2.13-3.2.17: a threshold `compared_with` a data message goes to the role that sends that data, has its
    unit and lies within its values' range; one threshold per role."""
    for k, f in enumerate(m.get("fields", [])):
        if "compared_with" not in f:
            continue
        at, fname = ["messages", i, "fields", k, "compared_with"], f"{m['name']}.{f['name']}"
        data = next((d for d in doc["messages"] if d["name"] == f["compared_with"]), None)
        if data is None or "record_values" not in data:
            report.add(path, doc, at, f"{fname}: compared_with '{f['compared_with']}', which is no message with record_values")
            continue
        if set(m["to"]) != set(data["from"]):
            report.add(path, doc, at, f"{fname}: goes to {'/'.join(m['to'])}, but {data['name']} comes from {'/'.join(data['from'])}")
        value = next((d for d in data.get("fields", []) if d["name"] == data["record_values"][0]), None)
        if value is None:
            continue                      # reported with the data message
        if f.get("unit") != value.get("unit"):
            report.add(path, doc, at, f"{fname}: unit {f.get('unit', 'none')!r}, but {data['name']}.{value['name']} "
                                      f"is in {value.get('unit', 'none')!r}")
        elif "range" in f and "range" in value:
            lo, hi = (to_fraction(v) for v in f["range"])
            vlo, vhi = (to_fraction(v) for v in value["range"])
            if lo < vlo or hi > vhi:
                report.add(path, doc, at, f"{fname}: range [{_num(lo)}, {_num(hi)}] reaches beyond "
                                          f"{data['name']}.{value['name']}'s [{_num(vlo)}, {_num(vhi)}]")
        for other in doc["messages"][:i]:
            if any(g.get("compared_with") == f["compared_with"] for g in other.get("fields", [])):
                report.add(path, doc, at, f"{fname}: {other['name']} already sets the threshold for {data['name']}")


def _lint_messages(path: Path, doc: dict, nodes_doc: dict, roles: set[str], report: Report, check_routes: bool) -> None:
    _lint_checksum(path, doc, report)
    _lint_enum_subsets(path, doc, report)
    for kind, key in (("enums", "values"), ("flags", "bits")):
        for name, e in doc[kind].items():
            if key not in e:
                continue                  # a subset: its values are its parent's
            values = list(e[key].values())
            if len(set(values)) != len(values):
                report.add(path, doc, [kind, name], f"{name}: two names share one value")
            for text_key in e.get("texts", {}):
                if text_key not in e[key]:
                    report.add(path, doc, [kind, name, "texts", text_key], f"{name}: text for unknown value {text_key}")
    seen_op: dict[int, str] = {}
    seen_name: set[str] = set()
    max_payload = doc["frame"]["max_payload"]
    names = {m["name"] for m in doc["messages"]}
    for i, m in enumerate(doc["messages"]):
        if "relayed_as" in m and m["relayed_as"] not in names:
            report.add(path, doc, ["messages", i, "relayed_as"], f"{m['name']}: relayed_as unknown message '{m['relayed_as']}'")
        elif "relayed_as" in m and not m.get("record"):
            report.add(path, doc, ["messages", i, "relayed_as"], f"{m['name']}: relayed_as is for records (`record: true`)")
        if "reply_to" in m:
            _lint_reply(path, doc, i, m, report)
        if "carried_in" in m:
            _lint_carried(path, doc, i, m, report)
        _lint_record_values(path, doc, i, m, report)
        _lint_compared(path, doc, i, m, report)
        if m.get("record") and (len(m["to"]) != 1 or m.get("broadcast")):
            report.add(path, doc, ["messages", i, "record"], f"{m['name']}: a record goes to one master role, not {'/'.join(m['to'])}"
                       f"{' or a broadcast' if m.get('broadcast') else ''}")

    for i, m in enumerate(doc["messages"]):
        at = ["messages", i]
        name = m["name"]
        if name in seen_name:
            report.add(path, doc, at, f"duplicate message name {name}")
        seen_name.add(name)
        if m["opcode"] in seen_op:
            report.add(path, doc, at + ["opcode"], f"{name}: duplicate opcode 0x{m['opcode']:02X}, already used by {seen_op[m['opcode']]}")
        seen_op.setdefault(m["opcode"], name)
        for side in ("from", "to"):
            for j, role in enumerate(m[side]):
                if role not in roles:
                    report.add(path, doc, at + [side, j], f"{name}: unknown node role '{role}' in `{side}`")
        _lint_fields(path, doc, at, m, max_payload, report)
        if check_routes and all(r in roles for r in m["from"] + m["to"]):
            _lint_routes(path, doc, at, m, nodes_doc, report)


def _lint_enum_subsets(path: Path, doc: dict, report: Report) -> None:
    """An enum has its own `values`, or is `subset_of` an enum with values and names some of them."""
    for name, e in doc["enums"].items():
        at = ["enums", name]
        if ("values" in e) == ("subset_of" in e):
            report.add(path, doc, at, f"{name}: needs either `values` or `subset_of` with `names`")
        elif "subset_of" in e:
            parent = doc["enums"].get(e["subset_of"])
            if "names" not in e:
                report.add(path, doc, at, f"{name}: `subset_of` needs `names`")
            elif parent is None or "values" not in parent:
                report.add(path, doc, at + ["subset_of"], f"{name}: subset_of '{e['subset_of']}' is no enum with its own values")
            else:
                for j, n in enumerate(e["names"]):
                    if n not in parent["values"]:
                        report.add(path, doc, at + ["names", j], f"{name}: {n} is not a value of {e['subset_of']}")
            if "texts" in e:
                report.add(path, doc, at + ["texts"], f"{name}: a subset takes its texts from nowhere; declare them on {e['subset_of']}")
        elif "names" in e:
            report.add(path, doc, at + ["names"], f"{name}: `names` belongs with `subset_of`")


def _lint_checksum(path: Path, doc: dict, report: Report) -> None:
    c = doc["frame"]["checksum"]
    crc = Checksum(c["name"], c["width"], c["poly"], c["init"], c["refin"], c["refout"], c["xorout"], c["check"])
    got = crc.compute(b"123456789")
    if got != c["check"]:
        report.add(path, doc, ["frame", "checksum", "check"],
                   f"checksum {c['name']}: check value 0x{c['check']:X} does not match the parameters (they give 0x{got:X})")


def _lint_fields(path: Path, doc: dict, at: list, m: dict, max_payload: int, report: Report) -> None:
    name = m["name"]
    fields = m.get("fields", [])
    names: list[str] = []
    bit_pos = 0
    for k, f in enumerate(fields):
        fat = at + ["fields", k]
        fname = f"{name}.{f['name']}"
        if f["name"] in names:
            report.add(path, doc, fat, f"{fname}: duplicate field name")
        bits = 8 if f["type"] in ("node", "char") else f.get("bits")
        if bits is None:
            report.add(path, doc, fat, f"{fname}: `bits` is required for type {f['type']}")
            continue
        if f["type"] in ("node", "char") and f.get("bits", 8) != 8:
            report.add(path, doc, fat, f"{fname}: a {f['type']} is 8 bits wide")
        if bits > 16 or bits not in (8, 16) and bits > 8:
            report.add(path, doc, fat, f"{fname}: {bits}-bit fields are not supported (use up to 8, or 16)")
        if bits == 16 and bit_pos % 8:
            report.add(path, doc, fat, f"{fname}: a 16-bit field must start on a byte boundary")
        if bits < 8 and bit_pos // 8 != (bit_pos + bits - 1) // 8:
            report.add(path, doc, fat, f"{fname}: a {bits}-bit field must not straddle a byte boundary")
        if f["type"] == "enum":
            _lint_enum_ref(path, doc, fat, fname, f, "enum", "enums", "values", bits, report)
        elif f["type"] == "flags":
            _lint_enum_ref(path, doc, fat, fname, f, "flags", "flags", "bits", bits, report)
        elif "enum" in f or "flags" in f:
            report.add(path, doc, fat, f"{fname}: only enum and flags fields take `enum`/`flags`")
        if f["type"] in ("uint", "int"):
            _lint_range(path, doc, fat, fname, f, bits, report)
        elif any(k in f for k in ("scale", "offset", "log10")):
            report.add(path, doc, fat, f"{fname}: only uint and int fields take scale, offset or log10")
        if "count" in f:
            if f["count"] not in names:
                report.add(path, doc, fat + ["count"], f"{fname}: count refers to '{f['count']}', which is not an earlier field")
            if k != len(fields) - 1:
                report.add(path, doc, fat, f"{fname}: an array must be the last field")
            if bits != 8:
                report.add(path, doc, fat, f"{fname}: array elements must be 8 bits wide")
        else:
            bit_pos += bits
        names.append(f["name"])
    if bit_pos % 8:
        report.add(path, doc, at, f"{name}: fields add up to {bit_pos} bits, not whole bytes")
    size = bit_pos // 8
    array = next((f for f in fields if "count" in f), None)
    if array is not None:
        count_field = next((f for f in fields if f["name"] == array["count"]), None)
        if count_field is not None:
            size += int(count_field.get("range", [0, 255])[1])
    if size > max_payload:
        report.add(path, doc, at, f"{name}: payload of up to {size} bytes exceeds the frame's max_payload {max_payload}")


def _lint_enum_ref(path: Path, doc: dict, fat: list, fname: str, f: dict, key: str, table: str, values_key: str,
                   bits: int, report: Report) -> None:
    ref = f.get(key)
    if ref is None:
        report.add(path, doc, fat, f"{fname}: type {key} needs `{key}:`")
    elif ref not in doc[table]:
        report.add(path, doc, fat + [key], f"{fname}: unknown {key} '{ref}'")
    else:
        biggest = max(enum_values_of(doc, ref).values() if table == "enums" else doc[table][ref][values_key].values(),
                      default=0)
        if biggest >= 1 << bits:
            report.add(path, doc, fat, f"{fname}: {key} {ref} has value {biggest}, wider than {bits} bits")


def _lint_range(path: Path, doc: dict, fat: list, fname: str, f: dict, bits: int, report: Report) -> None:
    lo_lim, hi_lim = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if f["type"] == "int" else (0, (1 << bits) - 1)
    if "log10" in f and ("scale" in f or "offset" in f):
        report.add(path, doc, fat, f"{fname}: log10 and scale/offset exclude each other")
        return
    if "log10" in f:
        lg = f["log10"]
        enc: Linear | Log10 = Log10(to_fraction(lg["ref"]), lg["per_decade"], bool(lg.get("saturate")), hi_lim)
    else:
        scale = to_fraction(f.get("scale", 1))
        if scale <= 0:
            report.add(path, doc, fat + ["scale"], f"{fname}: scale must be positive, not {f['scale']}")
            return
        enc = Linear(scale, to_fraction(f.get("offset", 0)))
    if "range" not in f:
        if "log10" in f or not enc.identity:  # type: ignore[union-attr]
            report.add(path, doc, fat, f"{fname}: a scaled field needs a physical `range`")
        return
    lo, hi = (to_fraction(v) for v in f["range"])
    if lo > hi:
        report.add(path, doc, fat + ["range"], f"{fname}: range [{f['range'][0]}, {f['range'][1]}] is empty")
        return
    raw_lo, raw_hi = enc.to_raw(lo), enc.to_raw(hi)
    if isinstance(enc, Log10) and enc.saturate:
        raw_lo, raw_hi = max(raw_lo, lo_lim), min(raw_hi, hi_lim)
    if raw_lo < lo_lim or raw_hi > hi_lim:
        unit = f" {f['unit']}" if "unit" in f else ""
        report.add(path, doc, fat + ["range"],
                   f"{fname}: range [{_num(lo)}, {_num(hi)}]{unit} needs raw {raw_lo}..{raw_hi}, "
                   f"but {bits} {'signed ' if f['type'] == 'int' else ''}bits hold {lo_lim}..{hi_lim}")


def _num(v: Fraction) -> str:
    return str(int(v)) if v.denominator == 1 else f"{float(v):g}"


def _lint_routes(path: Path, doc: dict, at: list, m: dict, nodes_doc: dict, report: Report) -> None:
    """Every sender must reach some receiver over one bus, and every receiver some sender (docs/decisions.md D2)."""
    nodes = nodes_doc["nodes"]

    def share(a: dict, b: dict) -> bool:
        return any(x.get("masters") is not None and y["bus"] == x["masters"] for x, y in ((a, b), (b, a)))

    senders = [n for n in nodes if n["role"] in m["from"]]
    receivers = [n for n in nodes if n["role"] in m["to"]]
    for side, group, other in (("from", senders, receivers), ("to", receivers, senders)):
        for role in dict.fromkeys(n["role"] for n in group):
            members = [n for n in group if n["role"] == role]
            if not any(share(n, o) for n in members for o in other if o is not n):
                peers = "/".join(m["to"] if side == "from" else m["from"])
                report.add(path, doc, at + [side], f"{m['name']}: {role} and {peers} are not on one bus (docs/decisions.md D2: masters relay between layers)")
    if m.get("broadcast"):
        for role in m["from"]:
            if not any(n.get("masters") for n in nodes if n["role"] == role):
                report.add(path, doc, at + ["from"], f"{m['name']}: only bus masters may broadcast, {role} masters no bus")
