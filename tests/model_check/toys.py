"""Small models with known answers, to test the engine independently of the spec."""
from model_check.gcl import Invariant, Model, Response, Rule, SymGroup, Var


def mutex(n: int = 3, lock: bool = True) -> Model:
    """n processes around a lock; without the lock mutual exclusion fails after two steps."""
    vs = [Var("lock", 1)] + [Var(f"pc{i}", 2) for i in range(n)]
    rules = []
    for i in range(n):
        free = "lock == 0" if lock else "True"
        rules += [Rule(f"enter{i}", f"pc{i} == 0 and {free}", (("lock", "1"), (f"pc{i}", "1")), actor=f"p{i}", ticks=1),
                  Rule(f"leave{i}", f"pc{i} == 1", (("lock", "0"), (f"pc{i}", "2")), actor=f"p{i}", ticks=1),
                  Rule(f"rest{i}", f"pc{i} == 2", ((f"pc{i}", "0"),), actor=f"p{i}", ticks=1)]
    inv = [Invariant("mutex", " + ".join(f"(pc{i} == 1)" for i in range(n)) + " <= 1")]
    return Model("mutex", vs, rules, inv)


def dining(n: int = 2) -> Model:
    """Philosophers taking the left fork then the right: the classic deadlock."""
    vs = [Var(f"f{i}", 1) for i in range(n)] + [Var(f"p{i}", 2) for i in range(n)]
    rules = []
    for i in range(n):
        left, right = f"f{i}", f"f{(i + 1) % n}"
        rules += [Rule(f"left{i}", f"p{i} == 0 and {left} == 0", ((left, "1"), (f"p{i}", "1"))),
                  Rule(f"right{i}", f"p{i} == 1 and {right} == 0", ((right, "1"), (f"p{i}", "2"))),
                  Rule(f"done{i}", f"p{i} == 2", ((left, "0"), (right, "0"), (f"p{i}", "0")))]
    return Model("dining", vs, rules)


def countdown(start: int = 5, stutter: bool = False) -> Model:
    """A timer that must reach zero; with `stutter` an unfair environment loop can delay it forever."""
    vs = [Var("t", start, init=start), Var("e", 1)]
    rules = [Rule("tick", "t > 0", (("t", "t - 1"),), actor="clock", ticks=1)]
    if stutter:
        rules.append(Rule("noise", "t > 0", (("e", "1 - e"),), actor=None))
    return Model("countdown", vs, rules, final="t == 0", responses=[Response("reaches_zero", "t > 0", "t == 0")])


def spin_forever() -> Model:
    """A system loop that is fair and never reaches the goal: a true liveness violation."""
    vs = [Var("a", 2), Var("goal", 1)]
    rules = [Rule("step", "a < 2", (("a", "a + 1"),), actor="sys", ticks=1),
             Rule("back", "a == 2", (("a", "1"),), actor="sys", ticks=1)]
    return Model("spin_forever", vs, rules, responses=[Response("goal", "a == 1", "goal == 1")])


def tokens(n: int = 4, hi: int = 2) -> Model:
    """n identical counters each bumped independently: symmetric, hi+1 ** n states, C(n+hi, n) orbits."""
    vs = [Var(f"c{i}", hi) for i in range(n)]
    rules = [Rule(f"bump{i}", f"c{i} < {hi}", ((f"c{i}", f"c{i} + 1"),)) for i in range(n)]
    return Model("tokens", vs, rules, final="True", symmetry=[SymGroup("counters", tuple((f"c{i}",) for i in range(n)))])


def torus(n: int = 4, size: int = 16) -> Model:
    """n counters modulo `size`, each stepped up or down: size ** n states, every one with 2n
    predecessors, so losing one state in a bitstate search cuts off nothing else."""
    vs = [Var(f"c{i}", size - 1) for i in range(n)]
    rules = []
    for i in range(n):
        rules += [Rule(f"up{i}", "True", ((f"c{i}", f"(c{i} + 1) % {size}"),)),
                  Rule(f"down{i}", "True", ((f"c{i}", f"(c{i} + {size - 1}) % {size}"),))]
    return Model("torus", vs, rules, final="True")
