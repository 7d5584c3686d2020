"""The successor function in C (issue 12: >= 500k states/s on one core), built like SPIN's pan.c.

The same model text that `fastgen` turns into Python is turned into one C
function per model, compiled once with the system C compiler into a shared
library cached by the hash of its source, and called through ctypes on a slice
of the frontier at a time. Its contract is the Python `edges` function's, plus
the in-layer deduplication `StateStore.add_layer` did with dicts:

- states are rows of W uint64 words (the packed int of compile.Layout, little
  end first); a frontier slice comes in as an (n, W) array;
- each state: invariants in order (the first that fails is the hit), then the
  rules in order; every successor is canonicalised (symmetry) and recorded as
  an edge: its rule, and the number of its successor among the distinct ones
  of this call, in first-seen order (a local open-addressing hash table);
  after the state, the number of edges so far (`ends`);
- no rule enabled and not `final`: a deadlock hit; an effect outside its
  variable's range: a RangeError hit naming rule, variable and value (raised
  in Python, with the message fastgen's code gives);
- it stops before a state whose successors might not fit the buffers and
  reports how many states it finished, so the caller calls again.

So ids, parents, edges, coverage, depth, verdicts and counterexamples are
those of the Python path (tests/model_check/test_native.py compares them).
Where there is no C compiler, or a model uses something this generator does not
translate (a divisor that is not a non-zero constant, a field wider than 64 bits),
`build` returns None and the engine keeps the Python path.
"""
from __future__ import annotations

import ast
import ctypes
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from model_check import expr
from model_check.gcl import Model
from model_check.storage import LOAD, StateStore

CC_FLAGS = ("-O1", "-shared", "-fPIC", "-std=c99", "-w")
# more compiler flags from the environment, for measurements and checks (e.g. "-DPSTAT": the
# parallel search's phase timers printed at exit; "-fsanitize=address,undefined"); part of the cache key
EXTRA_FLAGS_ENV = "ARACHNAE_NATIVE_CFLAGS"


def cc_flags() -> tuple[str, ...]:
    """CC_FLAGS and the environment's extra flags."""
    return CC_FLAGS + tuple(os.environ.get(EXTRA_FLAGS_ENV, "").split())
HIT_NONE, HIT_INVARIANT, HIT_DEADLOCK, HIT_RANGE, HIT_FULL = 0, 1, 2, 3, 4
MAX_EDGES = 1 << 16       # edges per call at most: bounds the buffers (about 3 MB for 3-word states)


class Unsupported(Exception):
    """A construct this generator does not translate: the model stays on the Python path."""


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "arachnae" / "model_check"


# -- expressions ------------------------------------------------------------------------

_C_CMP = {ast.Eq: "==", ast.NotEq: "!=", ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">="}
_C_BIN = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*"}
INT64 = (-(1 << 63), (1 << 63) - 1)


def _c(node: ast.expr, name) -> str:
    """C text of an expression of the shared language (model_check.expr); `name(id)` maps a name."""
    def e(n: ast.expr) -> str:
        return _c(n, name)

    if isinstance(node, ast.Name):
        return name(node.id)
    if isinstance(node, ast.Constant):
        v = int(node.value)
        if not INT64[0] < v <= INT64[1]:
            raise Unsupported(f"constant {v}")
        return f"((int64_t){v}LL)"
    if isinstance(node, ast.BoolOp):
        op = " && " if isinstance(node.op, ast.And) else " || "
        return "(" + op.join(e(v) for v in node.values) + ")"
    if isinstance(node, ast.UnaryOp):
        return f"(!{e(node.operand)})" if isinstance(node.op, ast.Not) else f"(-{e(node.operand)})"
    if isinstance(node, ast.BinOp):
        op = type(node.op)
        if op in _C_BIN:
            return f"({e(node.left)} {_C_BIN[op]} {e(node.right)})"
        # Python's floor division and modulo; only by a non-zero constant (no ZeroDivisionError to mimic)
        if not (isinstance(node.right, ast.Constant) and int(node.right.value) != 0):
            raise Unsupported("division by a non-constant")
        return f"{'pdiv' if op is ast.FloorDiv else 'pmod'}({e(node.left)}, {e(node.right)})"
    if isinstance(node, ast.Compare):
        return f"({e(node.left)} {_C_CMP[type(node.ops[0])]} {e(node.comparators[0])})"
    if isinstance(node, ast.IfExp):
        return f"({e(node.test)} ? {e(node.body)} : {e(node.orelse)})"
    if isinstance(node, ast.Call):
        a, b = (e(x) for x in node.args)
        return f"{'imin' if node.func.id == 'min' else 'imax'}({a}, {b})"   # type: ignore[attr-defined]
    raise Unsupported(ast.dump(node)[:40])


_PRELUDE = """\
#define _GNU_SOURCE           /* syscall (the parallel search's futex), clock_gettime (PSTAT) */
#include <stdint.h>
#include <string.h>
typedef int64_t I;
typedef uint64_t U;
static inline U getb(const U *s, unsigned sh, unsigned w) {
    unsigned k = sh >> 6, o = sh & 63;
    U m = w >= 64 ? ~(U)0 : (((U)1 << w) - 1);
    if (o + w <= 64) return (s[k] >> o) & m;
    return ((s[k] >> o) | (s[k + 1] << (64 - o))) & m;
}
static inline void setb(U *s, unsigned sh, unsigned w, U v) {
    unsigned k = sh >> 6, o = sh & 63;
    U m = w >= 64 ? ~(U)0 : (((U)1 << w) - 1);
    s[k] = (s[k] & ~(m << o)) | ((v & m) << o);
    if (o + w > 64) s[k + 1] = (s[k + 1] & ~(m >> (64 - o))) | ((v & m) >> (64 - o));
}
static inline I imin(I a, I b) { return a < b ? a : b; }
static inline I imax(I a, I b) { return a > b ? a : b; }
static inline I pdiv(I a, I b) { I q = a / b; return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q; }
static inline I pmod(I a, I b) { I r = a % b; return (r != 0 && ((r < 0) != (b < 0))) ? r + b : r; }
"""


# Stored rows are KW bytes (storage.StateStore), KW known when the C is generated: compared as
# 8-byte words (the last one overlapping the one before), no memcmp call (13% of a profile).
_KEQ = """\
static inline int keq(const uint8_t *a, const uint8_t *b) {
    U x, y;
    if (KW < 8) { x = y = 0; memcpy(&x, a, KW); memcpy(&y, b, KW); return x == y; }
    for (int o = 0; o + 8 < KW; o += 8) { memcpy(&x, a + o, 8); memcpy(&y, b + o, 8); if (x != y) return 0; }
    memcpy(&x, a + KW - 8, 8); memcpy(&y, b + KW - 8, 8);
    return x == y;
}"""


def predicate_texts(model: Model) -> list[str]:
    """The predicates the C code evaluates over stored states: `final`, then each response's
    trigger and goal (index 1 + 2k and 2 + 2k)."""
    return [model.final] + [t for r in model.responses for t in (r.trigger, r.goal)]


# Response checks on the stored graph (model_check.liveness's algorithm in one pass, issue 12):
# B = the states reachable from a trigger state (not a goal state) without passing a goal state.
# An iterative Tarjan over B finds its strongly connected components in reverse topological
# order, so when B is acyclic each state's longest tick path to the goal is known when its
# component closes (the bound K); a cyclic component is checked for weak fairness (every group
# enabled in all its states is taken inside it) there and then. Numbers only: no spec text.
L_BOUND, L_FAIR_ONLY, L_VIOLATION, L_NOMEM, L_OVERFLOW = 0, 1, 2, 3, 4
_GRAPH_COMMON = """\
#include <stdlib.h>
typedef struct { int64_t kind, bound; } LRes;
typedef struct { int32_t node, k; } Frame;
#define GOAL(V) ((mask[V] >> gb) & 1u)
#define TRIG(V) ((mask[V] >> tb) & 1u)
static int reserve(void **p, int64_t *cap, int64_t need, size_t size) {
    if (need <= *cap) return 1;
    int64_t c = *cap ? *cap : 4096;
    while (c < need) c *= 2;
    void *q = realloc(*p, (size_t)c * size);
    if (!q) return 0;
    *p = q; *cap = c; return 1;
}
#define PUSH(V) do { int32_t v_ = (V); \\
    if (off[v_ + 1] == off[v_]) { r->kind = %d; goto out; } \\
    if (!reserve((void **)&stk, &scap, sp + 1, sizeof *stk) || !reserve((void **)&fr, &fcap, cp + 1, sizeof *fr)) \\
        { r->kind = %d; goto out; } \\
    idx[v_] = low[v_] = counter++; stk[sp++] = v_; fr[cp].node = v_; fr[cp].k = 0; cp++; } while (0)
""" % (L_VIOLATION, L_NOMEM)
_GRAPH = """\
void NAME(int64_t n, const OT *off, const int32_t *dst, const RT *rule, const uint32_t *mask, int64_t tb, int64_t gb,
          const int32_t *ticks, const U *bit, int32_t *idx, int32_t *low, LRes *r) {
    int32_t *stk = 0; Frame *fr = 0;
    int64_t scap = 0, fcap = 0, sp = 0, cp = 0;
    int32_t counter = 0;
    int cyclic = 0;
    r->kind = %(bound)d; r->bound = 0;
    for (int64_t i = 0; i < n; i++) idx[i] = -1;
    for (int64_t root = 0; root < n; root++) {
        if (!TRIG(root) || GOAL(root) || idx[root] != -1) continue;
        PUSH((int32_t)root);
        while (cp > 0) {
            Frame *f = &fr[cp - 1];
            int32_t u = f->node;
            OT e = (OT)(off[u] + f->k);
            if (e < off[u + 1]) {
                f->k++;
                int32_t v = dst[e];
                if (GOAL(v)) continue;
                if (idx[v] == -1) PUSH(v);
                else if (idx[v] >= 0 && idx[v] < low[u]) low[u] = idx[v];
                continue;
            }
            cp--;
            if (cp > 0 && low[u] < low[fr[cp - 1].node]) low[fr[cp - 1].node] = low[u];
            if (low[u] != idx[u]) continue;
            /* u roots a component: stk[base .. sp-1]; a successor outside it is closed (idx -2) */
            int64_t base = sp - 1;
            while (stk[base] != u) base--;
            int self = 0;
            U always = ~(U)0, taken = 0;
            int64_t longest = 0;
            for (int64_t q = base; q < sp; q++) {
                int32_t w = stk[q];
                U en = 0;
                for (OT x = off[w]; x < off[w + 1]; x++) {
                    int32_t v = dst[x];
                    U b = bit[rule[x]];
                    int64_t c = ticks[rule[x]];
                    en |= b;
                    if (GOAL(v)) { if (c > longest) longest = c; continue; }
                    if (idx[v] >= idx[u]) { taken |= b; self |= v == w; }
                    else if (c + low[v] > longest) longest = c + low[v];
                }
                always &= en;
            }
            if (sp - base == 1 && !self) {
                if (longest > INT32_MAX) { r->kind = %(overflow)d; goto out; }
                low[u] = (int32_t)longest;
            } else {
                cyclic = 1;
                if ((always & ~taken) == 0) { r->kind = %(violation)d; goto out; }   /* a weakly fair cycle */
                for (int64_t q = base; q < sp; q++) low[stk[q]] = 0;
            }
            for (int64_t q = base; q < sp; q++) idx[stk[q]] = -2;
            sp = base;
        }
    }
    if (cyclic) r->kind = %(fair)d;
    else
        for (int64_t i = 0; i < n; i++)
            if (TRIG(i) && !GOAL(i) && low[i] > r->bound) r->bound = low[i];
out:
    free(stk);
    free(fr);
}
""" % {"bound": L_BOUND, "overflow": L_OVERFLOW, "violation": L_VIOLATION, "fair": L_FAIR_ONLY}


# The parallel search (model_check.parallel): `prun`, called on every thread at once (thread t),
# runs rounds over `bfs`'s hash table and rows until the search ends, a hit, `rounds` rounds, or
# arrays to grow; threads meet at barriers in C (no Python between the steps; a short spin, then
# a futex sleep). A round: thread 0 settles the last round and cuts the next states into
# consecutive slices (several per thread); then, the threads taking the slices as they come free
# (ptake), each slice
# - is expanded against the table as it is, read only; a successor not in it becomes a
#   candidate, deduplicated in the slice's own table, with its hash and where its probe of the
#   shared table stopped (slot, step);
# then (a barrier) each slice, in the same step (pput):
# - (kept if every slice before it finished) has its candidates marked: one an earlier slice has too is
#   that slice's (the earliest), the others are new, numbered in first-seen order;
# - takes its base id and edge place after the slice before it (the stored states plus the new
#   ones of the slices before), then writes each new candidate's row and parent at base + number
#   and claims a table slot for its id with a compare-and-swap from where its probe stopped (the
#   slots before it stay taken), and its edges, each candidate turned into its id, at their
#   place in the store.
# Three barriers a round (plan, expand, put). Table slots are prefetched a few candidates ahead
# (the claim and the mark stall on misses otherwise).
_PARALLEL = """\
#include <sched.h>
#ifdef __linux__
#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif
typedef struct {
    int32_t *ev; RULE_T *er; uint8_t *crow; int32_t *cpar; U *chash; int64_t *cslot, *cstep;
    int32_t *clocal, *ltable, *cown, *cidx;
    int64_t lbits, a, b, edge0, fresh, base, kept, ready;
    Res r;
} Slice;
typedef struct {
    uint8_t *keys; int32_t *parent, *table, *dst; RULE_T *rules; uint16_t *degree;
    int64_t width, tbits, tlimit, kcap, ecap, dcap, nk, ne, i, workers, edges_max, narrow, fan,
            seen_states, seen_edges, rounds, status, cap, bcount, bsense, nrounds, nsplit, ndropped,
            nslices, cexp, cmark, bsleep;
    Res hit;
} Ctx;
enum { P_RUN, P_DONE, P_PAUSE, P_GROW, P_HIT };
/* the threads meet: a short spin (a round's threads usually arrive within microseconds), then
   a sleep on a futex (Linux; sched_yield elsewhere), so a thread waiting for one that other load
   holds up gives its core away instead of spinning on it. bsense's low half is the futex word
   (little-endian rows: Builder); bsleep counts the sleepers, so the last thread makes a wake
   call only when one sleeps (its store and load, and a sleeper's count and the kernel's check
   of the word, are sequentially consistent: no wake is lost). */
#define SPIN 2000
static inline void prelax(void) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
}
static void pbarrier(Ctx *c, int64_t *sense) {
    int64_t s = !*sense;
    *sense = s;
    if (__atomic_add_fetch(&c->bcount, 1, __ATOMIC_ACQ_REL) == c->workers) {
        __atomic_store_n(&c->bcount, 0, __ATOMIC_RELAXED);
        __atomic_store_n(&c->bsense, s, __ATOMIC_SEQ_CST);
#ifdef __linux__
        if (__atomic_load_n(&c->bsleep, __ATOMIC_SEQ_CST))
            syscall(SYS_futex, (int32_t *)&c->bsense, FUTEX_WAKE_PRIVATE, INT32_MAX, NULL, NULL, 0);
#endif
        return;
    }
    for (int k = 0; __atomic_load_n(&c->bsense, __ATOMIC_ACQUIRE) != s; k++) {
        if (k < SPIN) { prelax(); continue; }
#ifdef __linux__
        __atomic_add_fetch(&c->bsleep, 1, __ATOMIC_SEQ_CST);
        syscall(SYS_futex, (int32_t *)&c->bsense, FUTEX_WAIT_PRIVATE, (int32_t)!s, NULL, NULL, 0);
        __atomic_sub_fetch(&c->bsleep, 1, __ATOMIC_SEQ_CST);
#else
        sched_yield();
#endif
    }
}
static void pexpand(const Ctx *c, Slice *q) {
    int64_t tbits = c->tbits;
    U tmask = ((U)1 << tbits) - 1, lmask = ((U)1 << q->lbits) - 1, s[W];
    U succ[NRULES * W]; int32_t sr[NRULES];
    uint8_t tb[W * 8];
    const uint8_t *keys = c->keys;
    const int32_t *table = c->table;
    int64_t ne = 0, nc = 0, i = q->a;
    Res *r = &q->r;
    for (int64_t d = 0; d < r->distinct; d++) q->ltable[q->clocal[d]] = -1;   /* last round's: empty again */
    r->kind = 0;
    for (; i < q->b; i++) {
        if (ne + NRULES > c->cap) { r->kind = HIT_FULL; break; }
        memset(s, 0, sizeof s);
        memcpy(s, keys + (size_t)i * KW, KW);      /* little-endian rows (Builder) */
        int64_t k = visit(s, succ, sr, r);
        if (k < 0) break;
        SUCC_SLOTS();
        for (int64_t j = 0; j < k; j++) {
            const U *t = succ + (size_t)j * W;
            U hh = hs_[j], slot = hh >> (64 - tbits);
            memcpy(tb, t, KW);
            int32_t got = -1;
            U step = 1;
            for (;; step++) {
                int32_t g = table[slot];
                if (g < 0) break;
                if (keq(keys + (size_t)g * KW, tb)) { got = g; break; }
                slot = (slot + step) & tmask;
            }
            if (got < 0) {                 /* not stored: a candidate, -1 - its number */
                U ls = hh & lmask;
                for (U lstep = 1;; lstep++) {
                    int32_t d = q->ltable[ls];
                    if (d < 0) {
                        d = (int32_t)nc++; q->ltable[ls] = d;
                        memcpy(q->crow + (size_t)d * KW, tb, KW);
                        q->cpar[d] = (int32_t)i; q->chash[d] = hh; q->cslot[d] = (int64_t)slot;
                        q->cstep[d] = (int64_t)step; q->clocal[d] = (int32_t)ls;
                    } else if (!keq(q->crow + (size_t)d * KW, tb)) {
                        ls = (ls + lstep) & lmask;
                        continue;
                    }
                    got = -1 - d;
                    break;
                }
            }
            q->ev[ne] = got; q->er[ne] = (RULE_T)sr[j]; ne++;
        }
        c->degree[i] = (uint16_t)k;
    }
    r->done = i; r->edges = ne; r->distinct = nc;
}
/* slice t's candidates: cown the earliest slice that has it, cidx its number there (new: among
   the new ones of slice t); the number of new ones */
static int64_t pmark(const Ctx *c, Slice *sl, int64_t t) {
    Slice *q = &sl[t];
    U lmask = ((U)1 << q->lbits) - 1;
    int64_t fresh = 0;
    for (int64_t d = 0; d < q->r.distinct; d++) {
        const uint8_t *tb = q->crow + (size_t)d * KW;
        int32_t own = (int32_t)t, at = -1;
        if (d + PF < q->r.distinct)         /* the slots PF candidates on, asked of memory now */
            for (int64_t u = 0; u < t; u++) __builtin_prefetch(&sl[u].ltable[q->chash[d + PF] & lmask]);
        for (int64_t u = 0; u < t && at < 0; u++) {
            U ls = q->chash[d] & lmask;
            for (U lstep = 1;; lstep++) {
                int32_t e = sl[u].ltable[ls];
                if (e < 0) break;
                if (keq(sl[u].crow + (size_t)e * KW, tb)) { own = (int32_t)u; at = e; break; }
                ls = (ls + lstep) & lmask;
            }
        }
        q->cown[d] = own;
        q->cidx[d] = at >= 0 ? at : (int32_t)fresh++;
    }
    return fresh;
}
/* the first free slot from `slot` on (probe step `step`) takes id, with a compare-and-swap:
   other threads claim slots at the same time */
static inline void pclaim(int32_t *table, U slot, U step, U tmask, int32_t id) {
    for (;; step++) {
        int32_t empty = -1;
        if (__atomic_load_n(&table[slot], __ATOMIC_RELAXED) < 0 &&
            __atomic_compare_exchange_n(&table[slot], &empty, id, 0, __ATOMIC_RELAXED, __ATOMIC_RELAXED))
            return;
        slot = (slot + step) & tmask;
    }
}
/* slots lo .. hi-1 of a new table emptied (-1) on one of several threads, before any prehash */
void pfill(int32_t *table, int64_t lo, int64_t hi) {
    memset(table + lo, 0xff, (size_t)(hi - lo) * sizeof *table);
}
/* rehash's part lo .. hi-1 on one of several threads at once (the slot order may differ) */
#define PPLACE(SLOT, ID) pclaim(table, (SLOT), 1, tmask, (ID))
void prehash(const uint8_t *keys, int64_t lo, int64_t hi, int32_t *table, int64_t tbits) {
    U tmask = ((U)1 << tbits) - 1;
    REHASH_LOOP(PPLACE);
}
static void pinsert(const Ctx *c, Slice *sl, int64_t t) {
    Slice *q = &sl[t];
    U tmask = ((U)1 << c->tbits) - 1;
    for (int64_t d = 0; d < q->r.distinct; d++) {
        if (d + PF < q->r.distinct) __builtin_prefetch(&c->table[q->cslot[d + PF]], 1);  /* as pmark */
        if (q->cown[d] != t) continue;
        int32_t id = (int32_t)(q->base + q->cidx[d]);
        memcpy(c->keys + (size_t)id * KW, q->crow + (size_t)d * KW, KW);
        c->parent[id] = q->cpar[d];
        pclaim(c->table, (U)q->cslot[d], (U)q->cstep[d], tmask, id);
    }
    int32_t *dst = c->dst + q->edge0;
    RULE_T *rules = c->rules + q->edge0;
    for (int64_t e = 0; e < q->r.edges; e++) {
        int32_t v = q->ev[e];
        if (v < 0) {
            int32_t d = -1 - v, u = q->cown[d];
            v = (int32_t)(u == t ? q->base + q->cidx[d] : sl[u].base + sl[u].cidx[q->cidx[d]]);
        }
        dst[e] = v;
        rules[e] = q->er[e];
    }
}
/* thread 0, before a round: the slices, or why not (the search is over, arrays to grow, a pause) */
static void pplan(Ctx *c, Slice *sl) {
    int64_t n = c->nslices;
    c->cexp = c->cmark = 0;
    for (int64_t u = 0; u < n; u++) sl[u].ready = 0;
    if (c->status != P_RUN) return;
    if (c->i == c->nk) { c->status = P_DONE; return; }
    if (c->rounds-- <= 0) { c->status = P_PAUSE; return; }
    int64_t room = c->tlimit - c->nk;            /* states the table takes at its load limit */
    if (room < n * NRULES) { c->status = P_GROW; return; }
    int64_t cap = room / n < c->edges_max ? room / n : c->edges_max;
    if (c->kcap - c->nk < n * cap || c->ecap - c->ne < n * cap) { c->status = P_GROW; return; }
    int64_t avail = c->nk - c->i;      /* may run on into the next layer's states stored already */
    int64_t per = avail > c->narrow ? (avail + n - 1) / n : avail;     /* a narrow frontier: one thread */
    if (per > cap / c->fan) per = cap / c->fan;
    if (per < 1) per = 1;
    if (c->dcap < c->i + n * per) { c->status = P_GROW; return; }
    for (int64_t u = 0; u < n; u++) {
        sl[u].a = c->i + u * per < c->nk ? c->i + u * per : c->nk;
        sl[u].b = sl[u].a + per < c->nk ? sl[u].a + per : c->nk;
    }
    c->cap = cap;
}
/* thread 0, after a round: the counts, a hit */
static void psettle(Ctx *c, Slice *sl) {
    int64_t nk = c->nk, ne = c->ne, last = 0, busy = 0;
    for (int64_t u = 0; u < c->nslices && sl[u].kept; u++) {
        nk += sl[u].fresh;
        ne += sl[u].r.edges;
        last = u;
    }
    for (int64_t u = 0; u < c->nslices; u++) busy += sl[u].a < sl[u].b;
    c->nrounds++;
    c->nsplit += busy > 1;
    c->ndropped += busy > last + 1;
    Res *r = &sl[last].r;
    c->seen_states += r->done - sl[0].a;
    c->seen_edges += ne - c->ne;
    c->nk = nk; c->ne = ne; c->i = r->done;
    /* successors per state to plan for: twice the highest mean of this round's slices, at least
       7/8 of the last round's plan; after a round that dropped slices, twice what was planned */
    int64_t fan = 1;
    for (int64_t u = 0; u <= last; u++) {
        int64_t m = sl[u].r.done > sl[u].a ? (2 * sl[u].r.edges + sl[u].r.done - sl[u].a - 1) / (sl[u].r.done - sl[u].a) : 1;
        if (m > fan) fan = m;
    }
    if (busy > last + 1) fan = 2 * c->fan;
    else if (fan < c->fan - c->fan / 8) fan = c->fan - c->fan / 8;    /* down slowly: fewer drops (158 -> 53 of 988 rounds) */
    c->fan = fan > NRULES ? NRULES : fan;
    if (r->kind != 0 && r->kind != HIT_FULL) { c->hit = *r; c->status = P_HIT; }
}
/* the next slice of a step for this thread to take (the threads share each step's slices
   as they come free: a thread held up by other load holds up the round less); -1 when none */
static inline int64_t ptake(const Ctx *c, int64_t *next) {
    int64_t k = __atomic_fetch_add(next, 1, __ATOMIC_RELAXED);
    return k < c->nslices ? k : -1;
}
#ifdef PSTAT    /* phase timers (ARACHNAE_NATIVE_CFLAGS=-DPSTAT): wall and CPU ns per thread, printed at exit */
#include <stdio.h>
#include <time.h>
enum { S_PLAN, S_EXPAND, S_INSERT, S_WAIT, S_N };
static const char *SNAME[S_N] = {"settle+plan", "expand", "mark+insert", "barrier"};
static int64_t swall[8][S_N], scpu[8][S_N];
static int64_t sedges, scand, sfresh, skept;     /* edges and candidates expanded, new states, edges kept */
#define PCOUNT(X, N) __atomic_add_fetch(&(X), (N), __ATOMIC_RELAXED)
static int64_t snow(clockid_t k) { struct timespec ts; clock_gettime(k, &ts); return ts.tv_sec * 1000000000LL + ts.tv_nsec; }
#define PT(T, PH, STMT) do { int64_t w0_ = snow(CLOCK_MONOTONIC), c0_ = snow(CLOCK_THREAD_CPUTIME_ID); STMT; \
    if ((T) < 8) { swall[T][PH] += snow(CLOCK_MONOTONIC) - w0_; scpu[T][PH] += snow(CLOCK_THREAD_CPUTIME_ID) - c0_; } } while (0)
__attribute__((destructor)) static void sprint(void) {
    for (int t = 0; t < 8; t++) {
        int64_t any = 0;
        for (int h = 0; h < S_N; h++) any += swall[t][h];
        if (!any) continue;
        fprintf(stderr, "PSTAT thread %d:", t);
        for (int h = 0; h < S_N; h++) fprintf(stderr, " %s %.3f/%.3f", SNAME[h], swall[t][h] / 1e9, scpu[t][h] / 1e9);
        fprintf(stderr, " (wall/cpu s)\\n");
    }
    if (sedges) fprintf(stderr, "PSTAT edges expanded %lld (kept %lld), candidates %lld, new states %lld\\n",
                        (long long)sedges, (long long)skept, (long long)scand, (long long)sfresh);
}
#else
#define PT(T, PH, STMT) do { STMT; } while (0)
#define PCOUNT(X, N) ((void)0)
#endif
/* slice k after the expansion: whether it is kept, its candidates marked, its base id and edge
   place (after slice k-1's: waits until that slice has them, taken before k and in hand), then
   its rows, table slots and edges; marking reads the tables of the slices before, so a slice's
   table is emptied at its next expansion */
static void pput(Ctx *c, Slice *sl, int64_t k) {
    Slice *q = &sl[k];
    q->kept = q->a < q->b;
    for (int64_t u = 0; u < k; u++) if (sl[u].r.done < sl[u].b) q->kept = 0;
    q->fresh = q->kept ? pmark(c, sl, k) : 0;
    if (k == 0) { q->base = c->nk; q->edge0 = c->ne; }
    else {
        const Slice *p = &sl[k - 1];
        for (int w = 0; !__atomic_load_n(&p->ready, __ATOMIC_ACQUIRE); w++)
            if (w < SPIN) prelax(); else sched_yield();
        q->base = p->base + p->fresh;
        q->edge0 = p->edge0 + (p->kept ? p->r.edges : 0);
    }
    __atomic_store_n(&q->ready, 1, __ATOMIC_RELEASE);
    PCOUNT(sedges, q->r.edges); PCOUNT(scand, q->r.distinct); PCOUNT(sfresh, q->fresh); PCOUNT(skept, q->kept ? q->r.edges : 0);
    if (q->kept) pinsert(c, sl, k);
    else q->r.edges = 0;
}
/* rounds: thread 0 plans (after settling the last round), then every thread expands slices,
   then marks and puts them: two barriers a round after the plan's */
void prun(Ctx *c, Slice *sl, int64_t t) {
    int64_t sense = 0, k;
    for (;;) {
        if (t == 0) PT(t, S_PLAN, pplan(c, sl));
        PT(t, S_WAIT, pbarrier(c, &sense));
        if (c->status != P_RUN) return;
        PT(t, S_EXPAND, while ((k = ptake(c, &c->cexp)) >= 0) pexpand(c, &sl[k]));
        PT(t, S_WAIT, pbarrier(c, &sense));
        PT(t, S_INSERT, while ((k = ptake(c, &c->cmark)) >= 0) pput(c, sl, k));
        PT(t, S_WAIT, pbarrier(c, &sense));
        if (t == 0) PT(t, S_PLAN, psettle(c, sl));
    }
}"""


class _Src:
    """The C text of one model, from its variables' bit fields (compile.Layout)."""

    def __init__(self, model: Model, shift: dict[str, int], width: dict[str, int], total_bits: int):
        self.model, self.shift, self.width = model, shift, width
        self.words = max(1, -(-total_bits // 64))
        self.row_bytes = StateStore.row_bytes(total_bits)

    def var(self, n: str, src: str = "s") -> str:
        return f"((I)getb({src}, {self.shift[n]}u, {self.width[n]}u))"

    def name(self, n: str) -> str:
        return self.var(n) if n in self.shift else f"d_{n}(s)"

    def source(self) -> str:
        m, W = self.model, self.words
        out = [_PRELUDE, _GRAPH_COMMON, f"#define W {W}", f"#define KW {self.row_bytes}", _KEQ]
        for n, text in m.defs:                  # definitions: pure functions of the state
            out.append(f"static inline I d_{n}(const U *s) {{ return {_c(expr.parse(text), self.name)}; }}")
        out += self.canon()
        out.append("static inline int inv_fail(const U *s) {")
        for i, inv in enumerate(m.invariants):
            out.append(f"    if (!({_c(expr.parse(inv.expr), self.name)})) return {i};")
        out.append("    return -1;\n}")
        out.append(f"static inline int is_final(const U *s) {{ return ({_c(expr.parse(m.final), self.name)}) != 0; }}")
        out += self.search()
        out += self.predicates()
        out += [_GRAPH.replace("OT", o).replace("RT", r).replace("NAME", f"respond_{o}_{r}")
                for o in ("int32_t", "int64_t") for r in ("uint8_t", "uint16_t")]
        return "\n".join(out) + "\n"

    def predicates(self) -> list[str]:
        """`pred(k, rows, ...)`: predicate k of `predicate_texts` over stored byte rows (storage)."""
        texts = predicate_texts(self.model)
        out = [f"static int p_{k}(const U *s) {{ return ({_c(expr.parse(t), self.name)}) != 0; }}"
               for k, t in enumerate(texts)]
        out.append("typedef int (*Pred)(const U *);")
        out.append("static const Pred PREDS[] = {" + ", ".join(f"p_{k}" for k in range(len(texts))) + "};")
        out.append("""\
/* predicates k0 .. k1-1 (at most 32) in each stored row: bit k - k0 of out[i] */
void preds(int64_t k0, int64_t k1, const uint8_t *rows, int64_t n, int64_t width, uint32_t *out) {
    U s[W];
    for (int64_t i = 0; i < n; i++) {
        const uint8_t *row = rows + (size_t)i * (size_t)width;
        memset(s, 0, sizeof s);
        for (int64_t j = 0; j < width; j++) s[j >> 3] |= (U)row[j] << (8 * (j & 7));   /* little-endian rows */
        uint32_t m = 0;
        for (int64_t k = k0; k < k1; k++) m |= (uint32_t)PREDS[k](s) << (k - k0);
        out[i] = m;
    }
}""")
        return out

    def canon(self) -> list[str]:
        """Sort each symmetry group's blocks ascending, in the group order (compile._canon_source)."""
        out = ["static inline void canon(U *t) {"]
        for g in self.model.symmetry:
            starts = [self.shift[b[0]] for b in g.blocks]
            width = sum(self.width[n] for n in g.blocks[0])
            if width > 64:
                raise Unsupported("symmetry block wider than 64 bits")
            k = len(starts)
            out.append("    {")
            out.append(f"        U w[{k}];")
            out += [f"        w[{i}] = getb(t, {st}u, {width}u);" for i, st in enumerate(starts)]
            out.append(f"        for (int i = 1; i < {k}; i++) {{ U x = w[i]; int j = i - 1;"
                       " while (j >= 0 && w[j] > x) { w[j + 1] = w[j]; j--; } w[j + 1] = x; }")
            out += [f"        setb(t, {st}u, {width}u, w[{i}]);" for i, st in enumerate(starts)]
            out.append("    }")
        out.append("}")
        return out

    def rule(self, ri: int) -> list[str]:
        """One rule: guard, effects in order (each reading the values assigned before it), range
        checks, the packed and canonical successor, and its edge."""
        m = self.model
        rule = m.rules[ri]
        out = [f"        if ({_c(expr.parse(rule.guard), self.name)}) {{", "            en = 1;"]
        current: dict[str, str] = {}
        for k, (target, value) in enumerate(rule.effect):
            hi = m.var(target).hi
            local = f"n{k}"
            out.append(f"            I {local} = "
                       f"{_c(expr.parse(value), lambda n: current.get(n) or self.name(n))};")
            out.append(f"            if ({local} < 0 || {local} > {hi}LL) "
                       f"{{ r->rule = {ri}; r->var = {m.vars.index(m.var(target))}; r->value = {local}; "
                       f"r->kind = {HIT_RANGE}; goto stop; }}")
            current[target] = local
        out.append("            memcpy(t, s, sizeof t);")
        for target, local in current.items():
            out.append(f"            setb(t, {self.shift[target]}u, {self.width[target]}u, (U){local});")
        if m.symmetry:
            out.append("            canon(t);")
        out.append(f"            EMIT({ri});")
        out.append("        }")
        return out

    def search(self) -> list[str]:
        n_rules = len(self.model.rules)
        R = max(n_rules, 1)
        rule_t = "uint8_t" if n_rules <= 256 else "uint16_t"      # storage.StateStore's rule array
        out = ["typedef struct { int64_t done, edges, distinct, kind, index, rule, var, value, layers; } Res;",
               "#define EMIT(RI) do { memcpy(succ + (size_t)k * W, t, sizeof t); sr[k++] = (RI); } while (0)",
               "/* the successors of s in rule order (canonical), their rules; -1 on a range hit (r says it) */",
               "static int64_t gen(const U *s, U *succ, int32_t *sr, Res *r) {",
               "    int64_t k = 0; U t[W]; int en = 0;"]
        for ri in range(n_rules):
            out += self.rule(ri)
        out += ["    (void)en;", "    return k;", "stop:", "    return -1;", "}"]
        out.append(f"""\
#define NRULES {R}
/* one state's check before its successors: 0 to go on, else the hit is in r */
static inline int64_t visit(const U *s, U *succ, int32_t *sr, Res *r) {{
    int bad = inv_fail(s);
    if (bad >= 0) {{ r->kind = {HIT_INVARIANT}; r->index = bad; return -1; }}
    int64_t k = gen(s, succ, sr, r);
    if (k == 0 && !is_final(s)) {{ r->kind = {HIT_DEADLOCK}; return -1; }}
    return k;
}}
/* expand: frontier rows, successors deduplicated within the call (model_check.parallel, bitstate) */
void expand(const U *front, int64_t n, U *out, int32_t *inv, int32_t *rules, int64_t *ends,
            int64_t cap, int32_t *table, int64_t tsize, Res *r) {{
    U tmask = (U)tsize - 1; int64_t ne = 0, nd = 0, i = 0;
    U succ[NRULES * W]; int32_t sr[NRULES];
    r->kind = 0;
    for (; i < n; i++) {{
        if (ne + NRULES > cap) {{ r->kind = {HIT_FULL}; break; }}
        int64_t k = visit(front + (size_t)i * W, succ, sr, r);
        if (k < 0) break;
        for (int64_t j = 0; j < k; j++) {{
            const U *t = succ + (size_t)j * W;
            U hh = 0x9E3779B97F4A7C15ULL;
            for (int q = 0; q < W; q++) {{ hh ^= t[q]; hh *= 0xBF58476D1CE4E5B9ULL; hh ^= hh >> 31; }}
            U slot = hh & tmask;
            int32_t got;
            for (U step = 1;; step++) {{
                got = table[slot];
                if (got < 0) {{ got = (int32_t)nd; table[slot] = got; memcpy(out + (size_t)nd * W, t, W * sizeof(U)); nd++; break; }}
                if (memcmp(out + (size_t)got * W, t, W * sizeof(U)) == 0) break;
                slot = (slot + step) & tmask;
            }}
            inv[ne] = got; rules[ne] = sr[j]; ne++;
        }}
        ends[i] = ne;
    }}
    r->done = i; r->edges = ne; r->distinct = nd;
}}
/* storage.mix64 of the row t, the top tbits bits: its first slot in the table */
#define HASH_SLOT() \\
    U hh = t[0] * 0x9E3779B97F4A7C15ULL; \\
    for (int q = 1; q < W; q++) hh = (hh ^ (hh >> 31) ^ t[q]) * 0xBF58476D1CE4E5B9ULL; \\
    hh = (hh ^ (hh >> 29)) * 0x94D049BB133111EBULL; \\
    U slot = hh >> (64 - tbits)
/* before the k successors in succ are probed: their hashes (hs_), each one's first slot and the
   row its id names asked of memory at once (a probe of a table many times the cache misses
   twice: the successors' misses overlap instead of queueing) */
#define SUCC_SLOTS() \\
    U hs_[NRULES]; \\
    for (int64_t j_ = 0; j_ < k; j_++) {{ \\
        const U *t = succ + (size_t)j_ * W; HASH_SLOT(); hs_[j_] = hh; __builtin_prefetch(&table[slot]); }} \\
    for (int64_t j_ = 0; j_ < k; j_++) {{ \\
        int32_t g_ = table[hs_[j_] >> (64 - tbits)]; if (g_ >= 0) __builtin_prefetch(keys + (size_t)g_ * KW); }}
/* bfs: expand the stored states i .. stop-1 (ids in breadth-first order) into the store itself
   (storage.StateStore): its hash table (mix64, triangular probing: the same slots as numpy's),
   byte rows, parents, edges and degrees. Stops before a state whose successors might not fit
   (keys up to klimit, edges up to ecap): the caller grows the arrays and calls again. */
void bfs(int64_t i, int64_t stop, uint8_t *keys, int64_t nk, int64_t klimit, int64_t width,
         int32_t *parent, int32_t *table, int64_t tbits, int32_t *dst, {rule_t} *rules, int64_t ne,
         int64_t ecap, uint16_t *degree, int64_t *layers, int64_t lcap, Res *r) {{
    U tmask = ((U)1 << tbits) - 1, s[W];
    U succ[NRULES * W]; int32_t sr[NRULES];
    uint8_t tb[W * 8];
    int64_t nl = 0;
    r->kind = 0;
    for (;; i++) {{
        if (i == stop) {{             /* the layer is done: the next is the states it found */
            if (nk == stop || nl == lcap) break;
            layers[nl++] = stop = nk;
        }}
        if (nk + NRULES > klimit || ne + NRULES > ecap) {{ r->kind = {HIT_FULL}; break; }}
        memset(s, 0, sizeof s);
        memcpy(s, keys + (size_t)i * KW, KW);      /* little-endian rows (Builder) */
        int64_t k = visit(s, succ, sr, r);
        if (k < 0) break;
        SUCC_SLOTS();
        for (int64_t j = 0; j < k; j++) {{
            const U *t = succ + (size_t)j * W;
            U hh = hs_[j], slot = hh >> (64 - tbits);
            memcpy(tb, t, KW);
            int32_t got;
            for (U step = 1;; step++) {{
                got = table[slot];
                if (got < 0) {{
                    got = (int32_t)nk; table[slot] = got;
                    memcpy(keys + (size_t)nk * KW, tb, KW);
                    parent[nk] = (int32_t)i; nk++;
                    break;
                }}
                if (keq(keys + (size_t)got * KW, tb)) break;
                slot = (slot + step) & tmask;
            }}
            dst[ne] = got; rules[ne] = ({rule_t})sr[j]; ne++;
        }}
        degree[i] = (uint16_t)k;
    }}
    r->done = i; r->edges = ne; r->distinct = nk; r->layers = nl;
}}
/* the first slot of stored row i (HASH_SLOT) */
static inline U rowslot(const uint8_t *keys, int64_t i, int64_t tbits) {{
    U t[W];
    memset(t, 0, sizeof t);
    memcpy(t, keys + (size_t)i * KW, KW);
    HASH_SLOT();
    return slot;
}}
/* the slots of rows lo .. hi-1, each asked of memory PF rows before it is probed (a rehash is
   random writes into a table many times the cache: the misses overlap instead of queueing);
   `place(slot, id)` puts one row */
#define PF 16
#define REHASH_LOOP(PLACE) do {{ \
    U ring_[PF]; \
    for (int64_t j_ = lo; j_ < hi && j_ < lo + PF; j_++) {{ \
        ring_[(j_ - lo) % PF] = rowslot(keys, j_, tbits); __builtin_prefetch(&table[ring_[(j_ - lo) % PF]], 1); }} \
    for (int64_t i_ = lo; i_ < hi; i_++) {{ \
        U at_ = ring_[(i_ - lo) % PF]; \
        if (i_ + PF < hi) {{ \
            U nx_ = rowslot(keys, i_ + PF, tbits); ring_[(i_ - lo) % PF] = nx_; __builtin_prefetch(&table[nx_], 1); }} \
        PLACE(at_, (int32_t)i_); \
    }} }} while (0)
#define RPLACE(SLOT, ID) do {{ U sl_ = (SLOT); \
    for (U step = 1; table[sl_] >= 0; step++) sl_ = (sl_ + step) & tmask; \
    table[sl_] = (ID); }} while (0)
/* the hash table (its slots not yet set) of the stored rows 0 .. n-1 (distinct), as bfs probes it */
void rehash(const uint8_t *keys, int64_t n, int64_t width, int32_t *table, int64_t tbits) {{
    U tmask = ((U)1 << tbits) - 1;
    int64_t lo = 0, hi = n;
    memset(table, 0xff, ((size_t)1 << tbits) * sizeof *table);      /* every slot -1: empty */
    REHASH_LOOP(RPLACE);
}}""")
        out.append(_PARALLEL.replace("RULE_T", rule_t).replace("HIT_FULL", str(HIT_FULL)))
        return out


class _LRes(ctypes.Structure):
    _fields_ = [("kind", ctypes.c_int64), ("bound", ctypes.c_int64)]


class _Res(ctypes.Structure):
    _fields_ = [(f, ctypes.c_int64) for f in ("done", "edges", "distinct", "kind", "index", "rule", "var", "value",
                                              "layers")]


@dataclass
class Chunk:
    """What one call of the C function produced for the first `done` states of its slice."""

    done: int                    # states fully expanded (their edges are below)
    distinct: np.ndarray         # (d, W) uint64: the distinct successors, first-seen order
    inv: np.ndarray              # per edge: index into `distinct`
    rules: np.ndarray            # per edge: the rule
    ends: np.ndarray             # per state: edges so far after it
    kind: int                    # HIT_* (HIT_FULL: buffers full, call again from `done`)
    index: int                   # invariant index (HIT_INVARIANT)
    rule: int = -1               # HIT_RANGE: the rule, variable index and value
    var: int = -1
    value: int = 0

    def hit(self, state: int | None = None) -> tuple | None:
        return _hit(self.kind, self.index, state)

    def range_message(self, model: Model) -> str:
        return range_message(model, self.rule, self.var, self.value)


def _hit(kind: int, index: int, state: int | None) -> tuple | None:
    """The violation as the Python `edges` reports it: (kind, index, state), or None."""
    if kind == HIT_INVARIANT:
        return ("invariant", index, state)
    return ("deadlock", -1, state) if kind == HIT_DEADLOCK else None


def range_message(model: Model, rule: int, var: int, value: int) -> str:
    """HIT_RANGE: the RangeError's text, as the Python `edges` words it."""
    return f"{model.rules[rule].name}: {model.vars[var].name} = {value}"


class Stop(NamedTuple):
    """Why and where `Native.bfs` stopped."""

    done: int                    # the first state not expanded
    kind: int                    # HIT_* (HIT_FULL: arrays full, grow them and call again)
    index: int                   # invariant index (HIT_INVARIANT)
    message: str                 # HIT_RANGE: the RangeError's text
    layers: list[int]            # where each layer the call went on to ends (first id after it)

    def hit(self) -> tuple | None:
        return _hit(self.kind, self.index, None)


class Native:
    """A compiled model: `expand(rows)` runs the C function over a slice of frontier rows."""

    def __init__(self, lib: ctypes.CDLL, words: int, rules: int):
        self.lib, self.words, self.n_rules = lib, words, max(rules, 1)
        self.fn = lib.expand
        self.fn.restype = None
        self.cap = 0
        self.res = _Res()
        self.layers = np.empty(1 << 10, np.int64)       # layer ends of one `bfs` call

    def _buffers(self, states: int) -> None:
        """Sized for `states` states at most (a small model's search stays small: issue 12's
        100 bytes/state), up to MAX_EDGES edges per call; grown, never shrunk."""
        want = max(self.n_rules, min(MAX_EDGES, states * self.n_rules))   # >= one state's edges
        if want > self.cap:
            self.cap = want
            self.tsize = 1 << (2 * want - 1).bit_length()      # load <= 0.5
            self.out = np.empty((want, self.words), np.uint64)
            self.inv = np.empty(want, np.int32)
            self.rules = np.empty(want, np.int32)
            self.table = np.empty(self.tsize, np.int32)

    def expand(self, rows: np.ndarray) -> Chunk:
        """Expand the frontier rows in order until done, a hit, or full buffers (`Chunk.done`)."""
        self._buffers(len(rows))
        rows = np.ascontiguousarray(rows, np.uint64)
        ends = np.empty(len(rows), np.int64)
        self.table.fill(-1)
        p = ctypes.c_void_p
        self.fn(p(rows.ctypes.data), ctypes.c_int64(len(rows)), p(self.out.ctypes.data), p(self.inv.ctypes.data),
                p(self.rules.ctypes.data), p(ends.ctypes.data), ctypes.c_int64(self.cap),
                p(self.table.ctypes.data), ctypes.c_int64(self.tsize), ctypes.byref(self.res))
        r = self.res
        return Chunk(int(r.done), self.out[:r.distinct].copy(), self.inv[:r.edges].copy(),
                     self.rules[:r.edges].copy(), ends[:r.done], int(r.kind), int(r.index),
                     int(r.rule), int(r.var), int(r.value))


    def bfs(self, store: StateStore, i: int, stop: int, model: Model) -> Stop:
        """Expand the stored states from i on, layer after layer (the current one ends before
        `stop`), into `store` (new states, parents, edges, degrees), until no new states, a hit,
        or full arrays (then call again from `Stop.done`; the arrays grow by a quarter before
        each call that needs it)."""
        fn = self.lib.bfs
        fn.restype = None
        store.rehash = self.rehash
        room = self.n_rules
        store.reserve(room, room, 0)
        keys, parent, dst, rule, degree = store.keys, store.parent, store.dst, store.rule, store.degree
        if degree.n != i:
            raise ValueError(f"bfs: state {i} expanded out of order ({degree.n} expanded)")
        klimit = min(len(keys.data), len(parent.data), int(LOAD * len(store.table)))
        degree.reserve(klimit - degree.n)            # every state stored by the end can be expanded
        ecap = min(len(dst.data), len(rule.data))
        p, n64 = ctypes.c_void_p, ctypes.c_int64
        fn(n64(i), n64(stop), p(keys.data.ctypes.data), n64(keys.n), n64(klimit), n64(store.width),
           p(parent.data.ctypes.data), p(store.table.ctypes.data), n64(store.table_bits),
           p(dst.data.ctypes.data), p(rule.data.ctypes.data), n64(dst.n), n64(ecap), p(degree.data.ctypes.data),
           p(self.layers.ctypes.data), n64(len(self.layers)), ctypes.byref(self.res))
        r = self.res
        keys.n = parent.n = int(r.distinct)
        dst.n = rule.n = int(r.edges)
        degree.n = int(r.done)
        message = range_message(model, int(r.rule), int(r.var), int(r.value)) if r.kind == HIT_RANGE else ""
        return Stop(int(r.done), int(r.kind), int(r.index), message, self.layers[:r.layers].tolist())

    def rehash(self, keys: np.ndarray, table: np.ndarray, bits: int) -> None:
        """Fill `table` (int32, 2^bits slots, not yet set: np.empty) with the ids of the stored byte rows."""
        p, n64 = ctypes.c_void_p, ctypes.c_int64
        self.lib.rehash.restype = None
        self.lib.rehash(p(keys.ctypes.data), n64(len(keys)), n64(keys.shape[1]), p(table.ctypes.data), n64(bits))

    def predicates(self, k0: int, k1: int, rows: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Predicates k0 .. k1-1 of `predicate_texts` (at most 32) in each stored byte row
        (storage.StateStore.keys): bit k - k0 of a uint32 per row."""
        if not 0 <= k0 <= k1 <= k0 + 32:
            raise ValueError(f"predicates {k0} .. {k1 - 1}: at most 32 at a time")
        rows = np.ascontiguousarray(rows, np.uint8)
        res = np.empty(len(rows), np.uint32) if out is None else out
        p, n64 = ctypes.c_void_p, ctypes.c_int64
        self.lib.preds(n64(k0), n64(k1), p(rows.ctypes.data), n64(len(rows)), n64(rows.shape[1]), p(res.ctypes.data))
        return res

    def respond(self, offsets: np.ndarray, dst: np.ndarray, rule: np.ndarray, mask: np.ndarray, trigger: int,
                goal: int, ticks: np.ndarray, bit: np.ndarray, work: np.ndarray) -> tuple[int, int]:
        """One response on the stored CSR graph: (L_* kind, bound K when L_BOUND). Its trigger
        and goal are bits `trigger` and `goal` of `mask` (uint32 per state, see `predicates`);
        `ticks` int32 and `bit` uint64 per rule; `work` int32 of shape (2, states), overwritten."""
        fn = getattr(self.lib, f"respond_{'int32_t' if offsets.dtype == np.int32 else 'int64_t'}_"
                               f"{'uint8_t' if rule.dtype == np.uint8 else 'uint16_t'}")
        fn.restype = None
        for a, dtype in ((offsets, offsets.dtype), (dst, np.int32), (rule, rule.dtype), (mask, np.uint32),
                         (ticks, np.int32), (bit, np.uint64), (work, np.int32)):
            if a.dtype != dtype or not a.flags.c_contiguous:
                raise TypeError(f"respond: an array of {a.dtype}, not contiguous {np.dtype(dtype)}")
        out = _LRes()
        p, n64 = ctypes.c_void_p, ctypes.c_int64
        fn(n64(len(mask)), p(offsets.ctypes.data), p(dst.ctypes.data), p(rule.ctypes.data), p(mask.ctypes.data),
           n64(trigger), n64(goal), p(ticks.ctypes.data), p(bit.ctypes.data), p(work[0].ctypes.data),
           p(work[1].ctypes.data), ctypes.byref(out))
        return int(out.kind), int(out.bound)


def c_source(model: Model, shift: dict[str, int], width: dict[str, int], total_bits: int) -> str:
    """The C source of `model`'s successor function (raises Unsupported)."""
    if any(w > 64 for w in width.values()):
        raise Unsupported("a field wider than 64 bits")
    return _Src(model, shift, width, total_bits).source()


class Builder:
    """The compiled model of one Compiled, made on the first call and kept (None where there is
    no compiler, an untranslated construct, or ARACHNAE_NATIVE=0 in the environment: the caller
    then uses the Python successor function). `cached()` says whether a call costs no compiler
    run, so a search can use C from its first state."""

    def __init__(self, model: Model, shift: dict[str, int], width: dict[str, int], total_bits: int):
        self.model, self.shift, self.width, self.total_bits = model, shift, width, total_bits
        self.done, self.native = False, None
        self._lib: Path | None | bool = False          # False: not worked out yet

    def lib(self) -> Path | None:
        """Where the shared object of this model is (or goes), None if there is none to be had."""
        if self._lib is False:
            self._lib = None
            if os.environ.get("ARACHNAE_NATIVE", "1") != "0" and sys.byteorder == "little":
                try:
                    self.src = c_source(self.model, self.shift, self.width, self.total_bits)
                    digest = hashlib.sha256((self.src + " ".join(cc_flags())).encode()).hexdigest()[:24]
                    self._lib = _cache_dir() / f"succ_{digest}.so"
                except Unsupported:
                    pass
        return self._lib      # type: ignore[return-value]

    def cached(self) -> bool:
        lib = self.lib()
        return self.done or (lib is not None and lib.exists())

    def __call__(self) -> Native | None:
        if not self.done:
            self.done, self.native = True, self._build()
        return self.native

    def _build(self) -> Native | None:
        lib = self.lib()
        if lib is None:
            return None
        if not lib.exists():
            cc = shutil.which(os.environ.get("CC", "cc"))
            if cc is None:
                return None
            try:
                lib.parent.mkdir(parents=True, exist_ok=True)
                with tempfile.TemporaryDirectory(dir=lib.parent) as tmp:
                    c_file, so = Path(tmp) / "succ.c", Path(tmp) / "succ.so"
                    c_file.write_text(self.src)
                    subprocess.run([cc, *cc_flags(), "-o", str(so), str(c_file)], check=True,
                                   capture_output=True, timeout=300)
                    os.replace(so, lib)             # atomic: a concurrent run sees all of it or nothing
            except (OSError, subprocess.SubprocessError):
                return None
        words = max(1, -(-self.total_bits // 64))
        return Native(ctypes.CDLL(str(lib)), words, len(self.model.rules))
