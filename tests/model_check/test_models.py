"""The three protocol models, built from the spec, against the properties issue 3 names."""
import pytest

from model_check import spec_adapter as sa
from model_check.engine import explore
from model_check.models import arbitration, id_retry, post


def test_seed_arbitration_collides_forever_with_two_slaves(spec):
    res = explore(arbitration.build(sa.arbitration(spec, "sensor"), "seed", 2), progress=False)
    v = res.violation
    assert v is not None and v.kind == "liveness" and v.prop.startswith("served_")
    cycle = [res.model.rules[s.rule].name for s in v.trace[v.loop_start + 1:]]
    assert cycle and set(cycle) == {"collision"}     # the lockstep retry, forever


def test_spec_rule_as_written_lets_a_slave_collide_without_bound(spec):
    """Only the colliders back off: a fresh request of a low rank keeps hitting the old one (three slaves: with
    two, the TPSC's reflex lead alone separates them; IRRC and USRC have none)."""
    p = sa.arbitration(spec, "sensor", "colliders")
    res = explore(arbitration.build(p, "spec", 3), progress=False)
    assert res.violation is not None and res.violation.prop == "collisions_bounded"


@pytest.mark.parametrize("bus", ["first", "sensor"])
def test_spec_arbitration_with_window_is_safe_and_bounded(spec, bus):
    p = sa.arbitration(spec, bus, "all")
    res = explore(arbitration.build(p, "spec"), progress=False)
    assert res.ok, res.violation
    assert res.never_fired == []
    bounds = res.bounds
    assert len(bounds) == len(p.slaves) and all(isinstance(k, int) and k > 0 for k in bounds.values())
    # a request can never be served faster than its own request slot plus its session
    for s in p.slaves:
        assert bounds[f"served_{s.short}"] >= 1 + s.fetch_slots + s.deliver_slots
    # the highest rank waits longest after a collision
    assert bounds[f"served_{p.slaves[-1].short}"] == max(bounds.values())


def test_arbitration_numbers_come_from_the_spec(spec):
    p = sa.arbitration(spec, "sensor")
    bus = spec.buses["sensor"]
    # spec arbitration rank_order declared_priority: buses.sensor.priority first, then ascending address
    rest = sorted((s for s in bus.slaves if s not in bus.priority), key=lambda s: spec.node(s).address)
    assert [s.short for s in p.slaves] == list(bus.priority) + rest
    assert [s.short for s in p.slaves][:2] == ["TPSC", "IRRC"]
    req = spec.message(p.request)
    gap = max(bus.turnaround_us, bus.idle_gap_chars * bus.char_time_us)     # spec buses: frame gap
    assert p.slot_us == pytest.approx((spec.frame.overhead + req.max_size) * bus.char_time_us + gap)


def test_id_retry_two_nodes_holds_with_bound_of_two_windows(spec):
    p = sa.identification(spec, "first")
    res = explore(id_retry.build(p, 2), progress=False)
    assert res.ok, res.violation
    window = p.req_ticks + p.timeout_ticks
    for name in p.slaves[:2]:
        assert res.bounds[f"decided_{name}"] == (p.retries + 1) * window   # at most two timeouts
    assert res.bounds["round_complete"] == 2 * (p.retries + 1) * window
    assert res.never_fired == []          # late, stale and lost ACKs all happen


def test_id_retry_catches_a_master_that_ignores_the_address(spec):
    """Mutation: accept any ACK while waiting -> a late ACK marks the wrong node."""
    m = id_retry.build(sa.identification(spec, "first"), 2)
    for i, r in enumerate(m.rules):
        if r.name.startswith("ack_stale_0_"):
            m.rules[i] = type(r)(r.name, r.guard, r.effect + (("e1", "1"),), r.actor, r.ticks, r.msc)
    m.validate()
    res = explore(m, progress=False)
    assert res.violation is not None and "MMC" in res.violation.prop


def test_sensor_bus_answer_to_the_retry_is_accepted_when_timed_to_its_first_byte(spec):
    """At 2400 baud an ID_ACK lasts longer than 10 ms; the spec times the reply to its first byte,
    so an answer to the retry can still be accepted (every rule fires)."""
    assert spec.protocol.response_timeout_to == "first_byte"
    res = explore(id_retry.build(sa.identification(spec, "sensor"), 1), progress=False)
    assert res.ok and res.never_fired == []


def test_timed_to_the_last_byte_the_sensor_bus_cannot_answer_in_time(spec):
    """The reading the spec rejects: a whole ID_ACK inside 10 ms is impossible at 2400 baud."""
    from dataclasses import replace

    from model_check.timing import id_timeout_check

    assert id_timeout_check(spec) == []
    last = replace(spec, protocol=replace(spec.protocol, response_timeout_to="last_byte"))
    problems = id_timeout_check(last)
    assert any(p.startswith("bus sensor:") for p in problems)
    res = explore(id_retry.build(sa.identification(last, "sensor"), 1), progress=False)
    assert any(n.startswith("ack_accepted_0_1") for n in res.never_fired)


def test_post_small_network_matches_oracle_without_and_with_symmetry(spec):
    p = sa.post(spec)
    plain = explore(post.build(p, legs=1, symmetry=False), progress=False)
    reduced = explore(post.build(p, legs=1, symmetry=True), progress=False)
    assert plain.ok and reduced.ok
    assert reduced.states < plain.states            # joints of the leg are interchangeable


def test_post_oracle_catches_a_wrong_quorum(spec):
    """Mutation: the model's rule tolerates two missing legs, the oracle (spec) does not."""
    import dataclasses
    p = sa.post(spec)
    loose = dataclasses.replace(p, quorums=[(n, k, least - 1, r) for n, k, least, r in p.quorums])
    model = post.build(loose, legs=None, symmetry=True)
    tree = post.Tree(p, None)
    names = {tree.var[s]: s for s in tree.var}
    model.final_checks = [("oracle", lambda v: post.oracle_mismatch(p, tree, names, v))]
    model.final_screen = lambda view: post.oracle_screen(p, tree, names, view)
    # only the legs vary (every other node answers), to keep the run short
    model.rules = [r for r in model.rules if not r.name.startswith("id_") or r.name.endswith("_present")
                   or r.name.startswith(("id_LCP", "id_JAC"))]
    res = explore(model, progress=False)
    assert res.violation is not None and res.violation.kind == "final-check"
    assert "HALTED" in res.violation.detail


def test_reflex_lead_is_modelled_with_the_collision_it_leaves(spec):
    """spec arbitration.reflex_lead_bits: the TPSC's reflex request may go alone while others wait (lead_TPSC)
    and may still collide with a deferred one restarting at the window's end (collision with TPSC sending).
    Three slaves of the sensor bus keep it small."""
    p = sa.arbitration(spec, "sensor")
    assert p.reflex == "TPSC" and not p.relay and p.reflex_gap_slots == int(250_000 // p.slot_us)
    model = arbitration.build(p, "spec", 3)
    res = explore(model, progress=False)
    assert res.ok, res.violation
    assert "lead_TPSC" in [r.name for r in model.rules] and res.never_fired == []
    lead = next(r for r in model.rules if r.name == "lead_TPSC")
    coll = next(r for r in model.rules if r.name == "collision")
    assert "nsend >= 2" in lead.guard and "nsend >= 2" in coll.guard     # both branches from the same state


def test_reflex_lead_without_the_rate_limit_starves_the_others(spec):
    """reflexes.min_interval_ms is what bounds the lead: a carrier allowed to raise reflex requests back to back
    overtakes a waiting slave forever (a liveness lasso through lead_TPSC)."""
    from dataclasses import replace
    p = replace(sa.arbitration(spec, "sensor"), reflex_gap_slots=0)
    res = explore(arbitration.build(p, "spec", 3), progress=False)
    v = res.violation
    assert v is not None and v.kind == "liveness" and v.prop != "served_TPSC"
    assert "lead_TPSC" in [res.model.rules[s.rule].name for s in v.trace[v.loop_start + 1:]]


def test_relay_bus_has_no_lead_rule(spec):
    """The SPU relays the TPSC's records on the first-level bus, but the spec bounds only how often the TPSC
    raises them, not how often they reach the SPU: no lead rule there (the model's docstring says why)."""
    p = sa.arbitration(spec, "first")
    assert p.reflex == "SPU" and p.relay and arbitration.lead_slave(p, "spec") is None
    assert not any(r.name.startswith("lead_") for r in arbitration.build(p, "spec", 3).rules)


@pytest.mark.parametrize("bus", ["first", "sensor"])
def test_fetch_is_labelled_with_the_spec_messages(spec, bus):
    """The chart's fetch arrows name the bus's fetch_message and each slave's record, as the spec declares them."""
    p = sa.arbitration(spec, bus)
    rules = {r.name: r for r in arbitration.build(p, "spec", 2).rules}
    for s in p.slaves[:2]:
        grant, record = rules[f"fetched_{s.short}"].msc
        assert grant.text == spec.buses[bus].fetch_message
        assert spec.message(record.text).record and spec.node(s.short).role in spec.message(record.text).senders
