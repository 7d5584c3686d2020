"""Bus arbitration (seed 3.2.2 "Message Scheduling") as a slotted guarded-command model.

Time is discrete: one tick is one slot, the time of one request frame plus the
frame gap (spec arbitration.slot: request_frame). Slaves whose record is
pending and who see the bus idle start their request at a slot boundary; two
or more starts in the same slot corrupt every frame (each slave reads a bad
echo). The master serves the first request that got through: it fetches the
record (grant + record frames) and, on the first-level bus, relays it to the
target. Record arrival at a slave is the environment and is never forced.

Variant `seed`: a corrupted request is resent in the next idle slot (the
document's rule) -- two pending slaves collide forever.
Variant `spec`: the spec's collision rule, in one of two scopes:
- `colliders` (the rule text as written): a slave that read a corrupt echo
  waits (rank + 1) * backoff_slots slots before it may send again;
- `all`: every slave hears a corrupt frame, so after it each slave of rank r
  may send only in the idle slot r * backoff_slots counted from the collision
  (a contention window of n * backoff_slots idle slots); after the window
  anyone may send again. Distinct ranks make collisions inside a window
  impossible, whether the requests are old or new.

The reflex lead (spec arbitration.reflex_lead_bits, seed 5.2), variant `spec`,
on the reflex source's bus (TPSC on the sensor bus, `ArbParams.reflex`): its
request starts reflex_lead_bits before any other on an idle line, so when it
and other requests wait for the same idle line it goes alone and the others
defer and stay pending (`lead_X`). It can still collide: a request deferred to
the end of a backoff window restarts on its timer, not on the line going idle,
and meets a reflex request starting then (`collision` stays possible whenever
several may send). The lead is bounded by the spec's rate: the source raises a
reflex request at most once per reflexes.min_interval_ms (`reflex_gap_slots`
whole slots, variable `rl`; tracecheck's `reflex_rate` rule checks the source's
raise notes against it); without that bound the source could overtake a waiting
slave forever (tests/model_check: a lasso through lead_X).

Not on a relay's bus (the SPU carrying the TPSC's records on the first-level
bus, `ArbParams.relay`): the spec bounds how often the source raises, not how
often its records reach the relay -- the hop below bunches them (a run had two
235 ms apart against min_interval 250 ms), so a lead there has no rate the
checker could use. There the relay's lead is abstracted like every slave's
rank stagger: requests waiting for the same idle line all start in that slot
and collide, and the window serves them by rank; the relay ranks first anyway
(buses.first.priority). tracecheck holds every trace to this model's K.

The send rule (`send_guard`) and the backoff a collision sets
(`collision_backoff`) are module-level so that the trace validator
(tracecheck) evaluates the very same expressions on a simulated or captured
bus trace instead of restating them.

Abstracted away, and checked on traces by tracecheck instead:
- the master's own transactions (polls, commands, POST, master_defer_slots):
  they occupy the line without changing any slave's state; the validator
  counts a request's wait and the window's slots without them;
- losses and line noise other than collisions: a request whose service met a
  lost or noise-corrupted frame is not held to the bound K;
- MOVE relay retries (protocol.move_retries) and record forwarding through
  the MCP: here one `delivered_X` step stands for the relay; the validator
  checks that every record reaching the MCP is relayed to its target and that
  MOVE_RELAYED is resent at most move_retries times, each after a STATUS_ACK
  that did not show the command applied;
- the sub-masters' relays (SPU, MMC, LCP) live on their own buses, which are
  polled (no contention to model) or modelled here as the sensor bus; the
  validator checks their exchanges with the one-talker and timeout rules.
"""
from __future__ import annotations

from model_check.expr import count_of
from model_check.gcl import Event, Invariant, Model, Response, Rule, Var
from model_check.spec_adapter import ArbParams

IDLE, PENDING, SESSION = 0, 1, 2
M_IDLE, M_FETCH, M_DELIVER = 0, 1, 2
VARIANTS = ("seed", "spec")


def window_slots(p: ArbParams, n: int) -> int:
    """Scope `all`: the contention window after a collision, n ranks of backoff_slots idle slots each."""
    return n * p.backoff_slots


def collision_backoff(p: ArbParams, rank: int) -> int:
    """Scope `colliders`: slots a slave that read a corrupt echo waits (spec arbitration.address_backoff)."""
    return (rank + 1) * p.backoff_slots


def lead_slave(p: ArbParams, variant: str, sl: list | None = None) -> int | None:
    """Index (among `sl`, default every slave) of the slave whose reflex requests lead on this bus (variant
    spec, spec arbitration.reflex_lead_bits > 0, the reflex's source on this bus), else None."""
    sl = p.slaves if sl is None else sl
    if variant != "spec" or p.reflex is None or p.relay:
        return None
    return next((i for i, s in enumerate(sl) if s.short == p.reflex), None)


def send_guard(p: ArbParams, variant: str, i: int, rank: int, n: int) -> str:
    """When slave i (rank `rank`, one of n) may start its request, over ph{i}, bo{i} and since.

    seed 3.2.2: a slave sends its request when the bus is idle; spec: only once its backoff ran out
    (colliders) or in its own idle slot of the window after a collision (all)."""
    if variant not in VARIANTS:
        raise ValueError(variant)
    if variant == "seed":
        return f"ph{i} == {PENDING}"
    if p.scope == "colliders":
        return f"ph{i} == {PENDING} and bo{i} == 0"
    return f"ph{i} == {PENDING} and (since == {window_slots(p, n)} or since == {rank * p.backoff_slots})"


def build(p: ArbParams, variant: str, slaves: int | None = None) -> Model:
    if variant not in VARIANTS:
        raise ValueError(variant)
    sl = p.slaves[:slaves] if slaves else p.slaves
    n = len(sl)
    spec = variant == "spec" and p.scope == "colliders"
    window = variant == "spec" and p.scope == "all"
    track = variant == "spec"
    W = window_slots(p, n)
    targets = sorted({s.target for s in sl})
    tcode = {t: i for i, t in enumerate(targets)}
    maxrem = max(max(s.fetch_slots, s.deliver_slots) for s in sl)
    c = lead_slave(p, variant, sl)
    gap = p.reflex_gap_slots if c is not None else 0
    vs: list[Var] = []
    for i, s in enumerate(sl):
        vs.append(Var(f"ph{i}", 2, doc=f"{s.short}: 0 idle, 1 record pending, 2 being served"))
        if spec:
            vs.append(Var(f"bo{i}", collision_backoff(p, s.rank), doc=f"{s.short}: backoff slots left"))
        if track:
            vs.append(Var(f"col{i}", p.max_collisions + 1, doc=f"{s.short}: collisions of this request"))
    if window:
        vs.append(Var("since", W, init=W, doc="idle slots since the last collision (W: window over)"))
    if gap:
        vs.append(Var("rl", gap, doc=f"slots before another reflex record may reach {sl[c].short} "
                                     f"(reflexes.min_interval_ms)"))
    vs += [Var("mph", 2, doc="master: 0 listening, 1 fetching, 2 relaying"), Var("msrc", max(n - 1, 1)),
           Var("mrem", maxrem, doc="slots left in the current frame exchange"),
           Var("mdst", max(len(targets) - 1, 1)), Var("err", 1, doc="monitor: record lost or duplicated")]

    def sends(i: int) -> str:
        return send_guard(p, variant, i, sl[i].rank, n)

    defs = [("nsend", count_of(sends(i) for i in range(n)))]
    nsend = "nsend"

    def tick_backoff(skip: int | None = None, idle: bool = False) -> list[tuple[str, str]]:
        out = [(f"bo{j}", f"max(bo{j} - 1, 0)") for j in range(n) if spec and j != skip]
        if window and idle:
            out.append(("since", f"min(since + 1, {W})"))
        return out + rate_tick()

    def rate_tick() -> list[tuple[str, str]]:
        return [("rl", "max(rl - 1, 0)")] if gap else []

    m = p.master
    rules: list[Rule] = []
    for i, s in enumerate(sl):
        if i == c and gap:                    # the source: every request carries a reflex, raised at most so often
            rules.append(Rule(f"arrive_{s.short}", f"ph{i} == {IDLE} and rl == 0",
                              ((f"ph{i}", str(PENDING)), ("rl", str(gap))),
                              actor=None, msc=(Event(s.short, None, "reflex record pending"),)))
            continue
        rules.append(Rule(f"arrive_{s.short}", f"ph{i} == {IDLE}", ((f"ph{i}", str(PENDING)),),
                          actor=None, msc=(Event(s.short, None, "record pending"),)))
    rules.append(Rule("idle_slot", f"mph == {M_IDLE} and {nsend} == 0", tuple(tick_backoff(idle=True)),
                      actor="bus", ticks=1))
    for i, s in enumerate(sl):
        eff = [(f"ph{i}", str(SESSION)), ("mph", str(M_FETCH)), ("msrc", str(i)), ("mrem", str(s.fetch_slots))]
        if track:
            eff.append((f"col{i}", "0"))
        rules.append(Rule(f"request_{s.short}", f"mph == {M_IDLE} and ({sends(i)}) and {nsend} == 1",
                          tuple(eff + tick_backoff(i, idle=True)), actor="bus", ticks=1,
                          msc=(Event(s.short, m, f"{p.request} (echo ok)"),)))
        if i == c:
            # spec arbitration.reflex_lead_bits: on an idle line the reflex request starts first, the others
            # hear its carrier and defer (they stay pending); the collision rule below remains possible too
            rules.append(Rule(f"lead_{s.short}", f"mph == {M_IDLE} and ({sends(i)}) and {nsend} >= 2",
                              tuple(eff + tick_backoff(i, idle=True)), actor="bus", ticks=1,
                              msc=(Event(s.short, m, f"{p.request} (reflex, first: the others defer)"),)))
    coll: list[tuple[str, str]] = []
    for i, s in enumerate(sl):
        if track:
            coll.append((f"col{i}", f"min(col{i} + 1, {p.max_collisions + 1}) if ({sends(i)}) else col{i}"))
        if spec:
            # spec arbitration.address_backoff: after a corrupt echo wait (rank + 1) backoff slots
            coll.append((f"bo{i}", f"{collision_backoff(p, s.rank)} if ({sends(i)}) else max(bo{i} - 1, 0)"))
    if window:
        coll.append(("since", "0"))     # every slave heard the corrupt frame: a new window starts
    coll += rate_tick()
    rules.append(Rule("collision", f"mph == {M_IDLE} and {nsend} >= 2", tuple(coll), actor="bus", ticks=1,
                      msc=(Event(m, None, f"{p.request} frames collide, every echo corrupt"),)))
    rules.append(Rule("busy_slot", f"mph != {M_IDLE} and mrem > 1", (("mrem", "mrem - 1"),) + tuple(tick_backoff()),
                      actor="bus", ticks=1))
    done = (("mph", str(M_IDLE)), ("msrc", "0"), ("mrem", "0"), ("mdst", "0"))
    for i, s in enumerate(sl):
        served = (("err", f"err if ph{i} == {SESSION} else 1"), (f"ph{i}", str(IDLE)))
        # spec buses.<bus>.fetch_message, answered with the slave's record (messages.<m>.record)
        fetch_ev = (Event(m, s.short, p.fetch or "fetch"), Event(s.short, m, s.record))
        if s.deliver_slots:
            eff = (("mph", str(M_DELIVER)), ("mrem", str(s.deliver_slots)), ("mdst", str(tcode[s.target])))
        else:
            eff = served + done
        rules.append(Rule(f"fetched_{s.short}", f"mph == {M_FETCH} and msrc == {i} and mrem == 1",
                          eff + tuple(tick_backoff()), actor="bus", ticks=1, msc=fetch_ev))
        if s.deliver_slots:
            rules.append(Rule(f"delivered_{s.short}", f"mph == {M_DELIVER} and msrc == {i} and mrem == 1",
                              served + done + tuple(tick_backoff()), actor="bus", ticks=1,
                              msc=(Event(m, s.target, f"record of {s.short}"),)))
    sessions = count_of(f"ph{i} == {SESSION}" for i in range(n))
    owner = " or ".join(f"(msrc == {i} and ph{i} == {SESSION})" for i in range(n))
    right = " and ".join(f"(msrc != {i} or mdst == {tcode[s.target]})" for i, s in enumerate(sl) if s.deliver_slots) \
        or "True"
    invs = [
        # seed 3.2.2: the MCP serves one slave at a time ("only one talker")
        Invariant("one_talker", f"({sessions}) == (0 if mph == {M_IDLE} else 1) and (mph == {M_IDLE} or {owner})"),
        Invariant("no_record_lost_or_duplicated", "err == 0"),
        Invariant("delivered_to_target", f"mph != {M_DELIVER} or ({right})"),
    ]
    if track:
        invs.append(Invariant("collisions_bounded", " and ".join(f"col{i} <= {p.max_collisions}" for i in range(n)),
                              doc="spec arbitration.max_collisions_per_request"))
    resp = [Response(f"served_{s.short}", f"ph{i} == {PENDING}", f"ph{i} == {IDLE}",
                     doc="every pending record is delivered") for i, s in enumerate(sl)]
    label = f"{variant}/{p.scope}" if variant == "spec" else variant
    return Model(name=f"arbitration[{p.bus},{label},{n} slaves]", vars=vs, rules=rules, invariants=invs,
                 responses=resp, defs=defs, tick_us=p.slot_us, participants=[m] + [s.short for s in sl],
                 notes=[f"seed {p.rule_section}; slot = {p.request} + frame gap = {p.slot_us:.0f} us"],
                 origin={"model": "arbitration", "bus": p.bus, "variant": variant})
