"""`arachnae docs`: the message reference from the spec, checked as HTML and in headless Chromium (issue 13)."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from arachnae.cli import main
from codegen.html import BOX_H, BOX_W, network_diagram, write_reference

from .conftest import offline, open_page

EVIL = '<script>window.__pwned = 1</script><b id="evil">x</b>&amp;'


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("docs") / "site"
    assert main(["docs", "--out", str(out)]) == 0
    return out / "index.html"


def test_reference_in_chromium(browser, reference, spec, tmp_path):
    loaded = open_page(browser, reference)
    page = loaded.page
    page.screenshot(path=str(tmp_path / "reference.png"), full_page=False)
    assert (tmp_path / "reference.png").stat().st_size > 10_000
    # the network: every node once, every bus a line below its master
    shown = page.eval_on_selector_all("#network g.node", "els => els.map(e => e.dataset.node)")
    assert sorted(shown) == sorted(n.short for n in spec.nodes)
    assert sorted(page.eval_on_selector_all("#network line.bus", "els => els.map(e => e.dataset.bus)")) == sorted(spec.buses)
    # every message with its layout table, citation and routes
    sections = page.eval_on_selector_all("section.message", "els => els.map(e => e.id)")
    assert sections == [f"msg-{m.name}" for m in spec.messages]
    for m in spec.messages:
        rows = page.eval_on_selector_all(f"#msg-{m.name} table.layout tr td:first-child", "els => els.map(e => e.textContent)")
        assert rows == [f.name for f in m.fields], m.name
        assert f"seed {m.section}" in page.inner_text(f"#msg-{m.name}")
        assert page.locator(f"#msg-{m.name} table.routes tr").count() >= 2, m.name
    psc = page.inner_text("#msg-XMIT_DATA_PSC table.layout")
    assert "raw × 0.005 + 4" in psc and "4.2 .. 5 V (raw 40..200)" in psc          # scale, offset, range and unit of a field
    assert page.locator("#post-rules tr").count() == 1 + len(spec.post.rules)
    for name in spec.arbitration:
        assert page.locator(f"#arb-{name}").count() == 1
    # the filter keeps the messages whose name matches
    page.fill("#filter", "MOVE")
    visible = page.eval_on_selector_all("section.message:not(.hidden)", "els => els.map(e => e.dataset.message)")
    assert visible == [m.name for m in spec.messages if "MOVE" in m.name] and visible
    assert loaded.errors == [] and offline(loaded.requests)


def test_spec_strings_are_escaped(browser, repo, tmp_path):
    from codegen.load import load_spec

    spec_dir = tmp_path / "spec"
    shutil.copytree(repo / "spec", spec_dir)
    messages = spec_dir / "messages.yaml"
    text = messages.read_text()
    doc = 'doc: "The node acknowledges ID_REQ by sending back its own address."'
    assert doc in text
    messages.write_text(text.replace(doc, f"doc: {json.dumps(EVIL)}"))
    page_path = write_reference(load_spec(spec_dir), tmp_path / "out")
    html = page_path.read_text()
    assert EVIL not in html and "&lt;script&gt;window.__pwned = 1&lt;/script&gt;" in html
    loaded = open_page(browser, page_path)
    assert loaded.page.evaluate("typeof window.__pwned") == "undefined"
    assert loaded.page.locator("#evil").count() == 0
    assert EVIL in loaded.page.inner_text("#msg-ID_ACK")                    # shown as the text it is
    assert loaded.errors == []


def test_network_boxes_do_not_overlap(spec):
    d = network_diagram(spec)
    assert len(d.boxes) == len(spec.nodes)
    boxes = sorted((b.x, b.y) for b in d.boxes)
    for i, (x1, y1) in enumerate(boxes):
        assert 0 <= x1 and x1 + BOX_W <= d.width and 0 <= y1 and y1 + BOX_H <= d.height
        for x2, y2 in boxes[i + 1:]:
            assert x2 >= x1 + BOX_W or abs(y2 - y1) >= BOX_H, ((x1, y1), (x2, y2))


def test_docs_out_must_be_a_folder(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("keep")
    assert main(["docs", "--out", str(f)]) == 1
    err = capsys.readouterr().err
    assert err == f"--out {f}: exists and is not a folder\n" and f.read_text() == "keep"


def test_docs_never_replaces_a_page_it_did_not_write(tmp_path, capsys):
    """issue 10.1: `docs --out .` in a folder with the user's own index.html keeps it; --force overrides."""
    page = tmp_path / "index.html"
    page.write_text("<html>my own page</html>")
    assert main(["docs", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "was not written by `arachnae docs`" in err
    assert page.read_text() == "<html>my own page</html>"
    assert main(["docs", "--out", str(tmp_path), "--force"]) == 0
    assert main(["docs", "--out", str(tmp_path)]) == 0          # our own page is replaced without --force
    assert "message reference" in page.read_text()
