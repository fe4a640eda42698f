"""halcompile documentation: the manual page and the reStructuredText page
made from a ``.comp`` file (``halcompile.gen_doc``).

The manual pages are rendered by ``man -l`` (and checked by groff with
every warning on); the reStructuredText pages are built together by
Sphinx with ``-W`` and the HTML is inspected for the tables and the
converted markup.
"""

from __future__ import annotations

import glob
import html
import os
import re
import shutil
import subprocess
import sys

import pytest
from helpers import data_path

from halcompile import CompError, gen_doc, parse_file
from halcompile.gen_doc import (
    document,
    file_name,
    install_doc,
    man_page,
    rst_page,
)

COMPS = str(data_path("comps"))
#: comps that must be in the corpus (the corpus grows: every .comp that
#: parses is documented)
KNOWN = {"hal_hcloop", "hcarrays", "hcbadc", "hcclamp", "hcdata", "hcddt",
         "hcdelay", "hclogic", "hcmux2", "hcnames", "hcrtapp", "hcsetup",
         "hcsingle", "hcsingle2", "hcslice", "hcuser", "hcuser2"}


def _parses(path: str) -> bool:
    try:
        parse_file(path)
    except CompError:
        return False
    return True


CORPUS = sorted(p for p in glob.glob(os.path.join(COMPS, "*.comp"))
                if _parses(p))
MAN = shutil.which("man")
GROFF = shutil.which("groff")
needs_man = pytest.mark.skipif(MAN is None, reason="man is not installed")

#: a component that uses every documentation declaration, with groff
#: markup of the kinds real files use
RICH = r'''component hcdocs "Documentation test with \\fBbold\\fR words";
description r"""
The \fBin\fR pin is copied to \fIout\fRput when \fBenable\fR is TRUE.
Stars * and back`ticks and pipes | and trailing_ underscores stay plain.
Tricky: \fB*\fR\fIx\fR, a\e\fBb\fR and (\fBq\fR).
.LP
A list:
.IP \(bu 4
first item
.IP \(bu
second item \(em with a dash
.PP
- a line that starts with a dash
.PP
1. not a numbered list
.TP
\fBterm\fR
the definition of the term
.PP
Ends with two colons::
.nf
loadrt hcdocs count=2
addf hcdocs.0 servo-thread
.fi
""";
pin in float in "the input";
pin out float out """first paragraph of a long doc.

second paragraph""";
pin in bit enable = TRUE;
pin out bit flag-#[3 : personality] if personality > 1 "flags";
param rw float gain = 1.0 r"gain \fBfactor\fR";
param r s32 calls;
function _ "copy in to out";
modparam int level = 3 "a level";
modparam string mode = "fast" "a mode";
modparam long big "a long";
notes r"""Some notes with \fIitalics\fR.

     indented line one
     indented line two
""";
examples r"""
.nf
net a => hcdocs.0.in
.fi
""";
see_also r"\fBhcmux2\fR(9), \fBhalcmd\fR(1)";
author "Ann Author";
author "Bob Builder";
license "GPL-2.0-or-later";
;;
out = enable ? in * gain : 0;
'''


@pytest.fixture(scope="module")
def rich(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = tmp_path_factory.mktemp("rich") / "hcdocs.comp"
    path.write_text(RICH)
    return str(path)


def sources(rich: str) -> list[str]:
    return CORPUS + [rich]


def test_the_corpus_is_there() -> None:
    assert KNOWN <= {os.path.basename(p)[:-5] for p in CORPUS}
    assert not _parses(os.path.join(COMPS, "hcbadsyntax.comp"))


def man_files(folder: str) -> list[str]:
    return sorted(glob.glob(os.path.join(folder, "*.9"))
                  + glob.glob(os.path.join(folder, "*.1")))


def render_man(path: str) -> str:
    """``man -l`` output of a page, 80 columns, no pager; fails on any
    message on stderr."""
    env = dict(os.environ, MANWIDTH="80", MANPAGER="cat", PAGER="cat",
               LC_ALL="C.UTF-8")
    proc = subprocess.run([MAN, "-l", path], capture_output=True, text=True,
                          env=env)
    assert proc.returncode == 0, proc.stderr
    assert "warning" not in (proc.stdout + proc.stderr).lower(), proc.stderr
    assert proc.stderr == "", proc.stderr
    # man drops bold/underline when not on a terminal, but be safe
    return re.sub(".\b", "", proc.stdout)


def squash(text: str) -> str:
    return re.sub(r"\s+", " ", text)


@pytest.fixture(scope="module")
def pages(tmp_path_factory: pytest.TempPathFactory, rich: str) -> str:
    """Every page of the corpus and of the rich comp, in one folder."""
    out = str(tmp_path_factory.mktemp("doc-pages"))
    for src in sources(rich):
        written = document(src, out)
        comp = parse_file(src)
        section = "1" if comp.option("userspace") else "9"
        assert written == [os.path.join(out, f"{comp.name}.{section}"),
                           os.path.join(out, comp.name + ".rst")]
    return out


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory, pages: str) -> str:
    """The reStructuredText pages built by Sphinx with -W (with the
    settings of our docs site that could matter)."""
    proj = tmp_path_factory.mktemp("sphinx-project")
    names = sorted(os.path.basename(p)[:-4]
                   for p in glob.glob(os.path.join(pages, "*.rst")))
    for name in names:
        shutil.copy(os.path.join(pages, name + ".rst"), proj)
    (proj / "conf.py").write_text(
        'project = "t"\nhighlight_language = "python"\n'
        'default_role = "code"\n')
    (proj / "index.rst").write_text(
        "Components\n==========\n\n.. toctree::\n\n"
        + "".join(f"   {n}\n" for n in names))
    out = proj / "_build"
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html",
         str(proj), str(out)], capture_output=True, text=True,
        cwd=str(proj))
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-6000:]
    assert "warning" not in proc.stderr.lower(), proc.stderr
    return str(out)


def page_html(site: str, name: str) -> str:
    with open(os.path.join(site, name + ".html"), encoding="utf-8") as f:
        text = f.read()
    body = text[text.index('<div class="body"'):]
    return body[:body.index('<div class="sphinxsidebar"')] \
        if '<div class="sphinxsidebar"' in body else body


def text_of(fragment: str) -> str:
    """The text of some HTML, white space squashed (no heading links)."""
    fragment = re.sub(r'<a class="headerlink".*?</a>', "", fragment)
    fragment = re.sub(r"</?(code|span|strong|em|a)\b[^>]*>", "", fragment)
    return squash(html.unescape(re.sub(r"<[^>]+>", " ", fragment))).strip()


def tables(page: str) -> dict[str, list[list[str]]]:
    """The tables of a page by section id: rows of cell texts."""
    out = {}
    for sec in re.finditer(r'<section id="([^"]+)">(.*?)(?=<section id=|$)',
                           page, re.S):
        table = re.search(r"<table.*?</table>", sec.group(2), re.S)
        if table:
            rows = re.findall(r"<tr.*?</tr>", table.group(0), re.S)
            out[sec.group(1)] = [
                [text_of(c) for c in re.findall(r"<t[hd].*?</t[hd]>", r,
                                                re.S)] for r in rows]
    return out


def hal_names(comp) -> list[str]:
    """The documented name of each pin and param of ``comp``."""
    inst = comp.prefix + ("" if comp.option("singleton") else ".N")
    return [inst + "." + re.sub("#+", lambda m: "M" * len(m.group(0)),
                                p.hal_name) for p in comp.pins + comp.params]


# ------------------------------------------------------------------ man


def test_man_page_has_the_sections_of_a_component_page(rich: str) -> None:
    for src in sources(rich):
        comp = parse_file(src)
        text = man_page(comp)
        heads = re.findall(r"^\.SH (.*)$", text, re.M)
        want = ["NAME", "SYNOPSIS"]
        want += ["DESCRIPTION"] if comp.description else []
        want += ["FUNCTIONS"] if comp.functions else []
        want += ["PINS"]
        want += ["PARAMETERS"] if comp.params else []
        want += ["NOTES"] if comp.notes else []
        want += ["EXAMPLES"] if comp.examples else []
        want += ["SEE ALSO"] if comp.see_also else []
        want += ["AUTHOR"] if comp.authors else []
        want += ["LICENSE"]
        assert heads == want, src
        section = "1" if comp.option("userspace") else "9"
        assert re.search(rf'^\.TH "{comp.name.upper()}" {section} '
                         r'"\d{4}-\d\d-\d\d" "halsdk" "HAL Component"$', text,
                         re.M), src


@needs_man
def test_man_pages_render_without_warnings(pages: str) -> None:
    files = man_files(pages)
    assert len(files) == len(CORPUS) + 1
    for path in files:
        name, section = os.path.basename(path).rsplit(".", 1)
        comp = parse_file(os.path.join(COMPS, name + ".comp")) \
            if name != "hcdocs" else None
        text = render_man(path)
        assert text.lstrip().startswith(f"{name.upper()}({section})"), \
            text[:200]
        heads = ["NAME", "SYNOPSIS", "PINS", "LICENSE"]
        heads += ["FUNCTIONS"] if section == "9" else []
        for head in heads:
            assert re.search(rf"^{head}$", text, re.M), (path, head)
        if comp is not None:
            flat = squash(text)
            for hal in hal_names(comp):
                assert hal in flat, (path, hal)
            assert "GPL" in flat


@pytest.mark.skipif(GROFF is None, reason="groff is not installed")
def test_groff_finds_nothing_to_warn_about(pages: str) -> None:
    for path in man_files(pages):
        proc = subprocess.run([GROFF, "-man", "-ww", "-z", "-Tutf8", path],
                              capture_output=True, text=True)
        assert proc.returncode == 0 and proc.stderr == "", (path,
                                                            proc.stderr)


@needs_man
def test_man_page_facts_of_the_corpus(pages: str) -> None:
    def page(name: str, section: str = "9") -> str:
        return squash(render_man(os.path.join(pages, f"{name}.{section}")))

    text = page("hcsetup")
    assert "loadrt hcsetup [count=N|names=name1[,name2...]] [offset=N] " \
        "[unused=N]" in text
    assert "count [default: 2]" in text           # option default_count
    assert "offset [default: 100]" in text
    assert "added to each instance's base" in text
    assert "hcsetup.N.update" in text
    assert "hcsetup.N.step s32 rw (default: 1)" in text
    assert "hcsetup.N.base s32 r " in text
    assert "hcsetup.N.ninst s32 out the module-level count" in text
    assert "floating-point" not in text            # nofp function

    text = page("hcsingle")                        # singleton: one instance
    assert "loadrt hcsingle NAME" not in text
    assert re.search(r"SYNOPSIS loadrt hcsingle FUNCTIONS hcsingle PINS "
                     r"hcsingle\.value s32 out hcsingle\.in s32 in", text)
    assert "count" not in text and ".N" not in text

    text = page("hcdata")                          # count_function
    assert "count=N" not in text and "names=" not in text
    assert "hcdata.N.which s32 out" in text

    text = page("hclogic")                         # personality
    assert "[personality=P,P,...]" in text
    assert "personality [default: 259]" in text
    assert "hclogic.N.in-MM bit in (MM from 00; personality & 0xff items, " \
        "at most 16)" in text
    assert "hclogic.N.xor bit out [if personality & 0x400]" in text

    text = page("hal_hcloop")      # hal_ prefix: not in the item names
    assert "loadrt hal_hcloop [count=N" in text
    assert "hcloop.N (requires a floating-point thread)" in text
    assert "hcloop.N.example float out (default: 4.25)" in text
    assert "hal-hcloop" not in text and "hal_hcloop.N" not in text

    text = page("hcarrays")
    assert "hcarrays.N (requires a floating-point thread) sum the inputs" \
        in text
    assert "hcarrays.N.count-calls PINS" in text   # nofp, no doc
    assert "hcarrays.N.in-M float in (M=0..3) inputs" in text
    assert "hcarrays.N.idx.MM.v s32 out (MM=00..02) (default: 7)" in text
    assert "hcarrays.N.count u32 io (default: 0x10) an io pin" in text
    assert "hcarrays.N.in float in in is a C name" in text
    assert "hcarrays.N.big-param float r (default: 1e20)" in text
    assert "hcarrays.N.sum float out (default: -1.5)" in text

    text = page("hcmux2")
    assert "DESCRIPTION A two-input multiplexer, written as a test of " \
        "halcompile." in text
    assert "SEE ALSO mux4(9)" in text
    assert "hcmux2.N.sel bit in TRUE selects in1, FALSE selects in0" in text

    text = page("hcuser", "1")     # userspace: a program, section 1
    assert text.lstrip().startswith("HCUSER(1) HAL Component HCUSER(1)")
    assert "loadusr hcuser [count=N|names=name1[,name2...]] [ARGUMENT...]" \
        in text
    assert "FUNCTIONS" not in text
    assert "hcuser.N.offset float rw (default: 0.5) added to out" in text
    text = page("hcuser2", "1")
    assert "SYNOPSIS loadusr hcuser2 PINS hcuser2.nargs s32 out" in text

    text = page("hcddt")
    assert "AUTHOR halsdk tests LICENSE GPL" in text
    assert "NAME hcddt - Compute the derivative of the input function" \
        in text


@needs_man
def test_man_page_of_every_declaration(pages: str) -> None:
    raw = render_man(os.path.join(pages, "hcdocs.9"))
    text = squash(raw)
    assert "NAME hcdocs - Documentation test with bold words" in text
    assert ("loadrt hcdocs [count=N|names=name1[,name2...]] "
            "[personality=P,P,...] [level=N] [mode=S] [big=N]") in text
    assert 'mode [default: "fast"]' in text and "a mode" in text
    assert "The in pin is copied to output when enable is TRUE." in text
    assert "\u2022 first item" in text or "o first item" in text
    assert "second item \u2014 with a dash" in text or \
        "second item -- with a dash" in text
    # no-fill text keeps its lines
    assert re.search(r"^ +loadrt hcdocs count=2\n +addf hcdocs\.0 "
                     r"servo-thread$", raw, re.M)
    assert re.search(r"^ +indented line one\n +indented line two$", raw,
                     re.M)
    assert "hcdocs.N.flag-M bit out (M from 0; personality items, at " \
        "most 3) [if personality > 1] flags" in text
    assert "hcdocs.N.enable bit in (default: TRUE)" in text
    assert "first paragraph of a long doc. second paragraph" in text
    assert "hcdocs.N.gain float rw (default: 1.0) gain factor" in text
    assert "NOTES Some notes with italics." in text
    assert "EXAMPLES net a => hcdocs.0.in" in text
    assert "SEE ALSO hcmux2(9), halcmd(1)" in text
    assert "AUTHOR Ann Author Bob Builder LICENSE GPL-2.0-or-later" in text


def test_man_escapes_generated_text() -> None:
    from halcompile import parse
    comp = parse('component esc "x";\npin out float a-b = -1e20;\n'
                 "function _;\nlicense \"GPL\";\n;;\n", "esc.comp")
    text = man_page(comp, date="2024-01-02")
    assert '.TH "ESC" 9 "2024-01-02"' in text
    assert r"\fBesc.\fIN\fB.a\-b\fR float out (default: \-1e20)" in text
    assert r"esc \- x" in text


def test_page_date_is_reproducible(monkeypatch, rich: str) -> None:
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "86400")
    assert '"1970-01-02"' in man_page(parse_file(rich))
    monkeypatch.delenv("SOURCE_DATE_EPOCH")
    os.utime(rich, (1_700_000_000, 1_700_000_000))
    assert '"2023-11-14"' in man_page(parse_file(rich))


# ------------------------------------------------------------------ rst


def test_rst_pages_build_with_sphinx_W(site: str, rich: str) -> None:
    for src in sources(rich):
        name = parse_file(src).name
        assert os.path.getsize(os.path.join(site, name + ".html")) > 1000


def test_rst_tables_hold_the_pins_and_params(site: str, rich: str) -> None:
    for src in sources(rich):
        comp = parse_file(src)
        found = tables(page_html(site, comp.name))
        names = hal_names(comp)
        pins = found["pins"]
        assert pins[0] == ["Name", "Type", "Direction", "Default",
                           "Description"]
        assert len(pins) == len(comp.pins) + 1, src
        for row, pin, hal in zip(pins[1:], comp.pins, names):
            assert row[0].split()[0] == hal
            assert row[1:3] == [pin.type, pin.direction]
            assert row[3] == (pin.default or "")
        if comp.params:
            params = found["parameters"]
            assert len(params) == len(comp.params) + 1
            for row, par, hal in zip(params[1:], comp.params,
                                     names[len(comp.pins):]):
                assert row[0].split()[0] == hal
                assert row[1:4] == [par.type, par.direction,
                                    par.default or ""]
        else:
            assert "parameters" not in found
        if not comp.functions:
            assert "functions" not in found
            continue
        functions = found["functions"]
        assert functions[0] == ["Function", "Floating point", "Description"]
        assert [r[1] for r in functions[1:]] == [
            "yes" if f.fp else "no" for f in comp.functions]


def test_rst_facts_of_the_corpus(site: str) -> None:
    page = page_html(site, "hcarrays")
    rows = {r[0].split()[0]: r for r in tables(page)["pins"][1:]}
    assert rows["hcarrays.N.in-M"] == ["hcarrays.N.in-M M=0..3", "float",
                                       "in", "", "inputs"]
    assert rows["hcarrays.N.count"][3:] == ["0x10", "an io pin"]
    funcs = tables(page)["functions"]
    assert funcs[1] == ["hcarrays.N", "yes", "sum the inputs"]
    assert funcs[2] == ["hcarrays.N.count-calls", "no", ""]
    page = page_html(site, "hclogic")
    text = text_of(page)
    assert "loadrt hclogic [count=N|names=name1[,name2...]] " \
        "[personality=P,P,...]" in text
    rows = {r[0].split()[0]: r for r in tables(page)["pins"][1:]}
    assert rows["hclogic.N.and"][0] == \
        "hclogic.N.and only if personality & 0x100"
    assert rows["hclogic.N.in-MM"][0] == \
        "hclogic.N.in-MM MM from 00; personality & 0xff items, at most 16"
    text = text_of(page_html(site, "hcsingle"))
    assert "loadrt hcsingle" in text and "count" not in text
    text = text_of(page_html(site, "hcsetup"))
    assert "offset (default: 100) A module parameter: an integer. " \
        "added to each instance’s base" in text.replace("'", "’")


def test_rst_converts_the_groff_markup(site: str) -> None:
    page = page_html(site, "hcdocs")
    assert "<strong>bold</strong>" in page.split("</h1>")[0]
    desc = page[page.index('<section id="description">'):
                page.index('<section id="functions">')]
    assert "The <strong>in</strong> pin is copied to <em>out</em>put when " \
        "<strong>enable</strong> is TRUE." in desc
    assert "Stars * and back`ticks and pipes | and trailing_ underscores " \
        "stay plain." in html.unescape(desc)
    assert "Tricky: <strong>*</strong><em>x</em>, a\\<strong>b</strong> " \
        "and (<strong>q</strong>)." in desc
    items = re.findall(r"<li><p>(.*?)</p></li>", desc, re.S)
    assert items == ["first item", "second item \u2014 with a dash"]
    assert "<p>- a line that starts with a dash</p>" in desc
    assert "<p>1. not a numbered list</p>" in desc
    assert "<ol" not in desc
    assert re.search(r"<dt><strong>term</strong></dt>\s*<dd><p>the "
                     r"definition of the term</p>", desc)
    assert "<p>Ends with two colons::</p>" in desc
    assert re.search(r"<pre>(<span></span>)?loadrt hcdocs count=2\naddf "
                     r"hcdocs.0 servo-thread\n?</pre>", desc)
    notes = page[page.index('<section id="notes">'):]
    assert "Some notes with <em>italics</em>." in notes
    assert re.search(r"<pre>(<span></span>)?indented line one\nindented "
                     r"line two\n?</pre>", notes)
    pins = {r[0].split()[0]: r for r in tables(page)["pins"][1:]}
    assert pins["hcdocs.N.out"][4] == \
        "first paragraph of a long doc. second paragraph"
    assert pins["hcdocs.N.flag-M"][0] == ("hcdocs.N.flag-M M from 0; "
                                          "personality items, at most 3 "
                                          "only if personality > 1")
    assert pins["hcdocs.N.enable"][3] == "TRUE"
    params = {r[0].split()[0]: r for r in tables(page)["parameters"][1:]}
    assert params["hcdocs.N.gain"][4] == "gain factor"
    assert "gain <strong>factor</strong>" in page
    assert "<strong>hcmux2</strong>(9), <strong>halcmd</strong>(1)" in page
    text = text_of(page)
    assert "See also hcmux2(9), halcmd(1) Author" in text
    assert "Author Ann Author Bob Builder" in text
    assert "License GPL-2.0-or-later" in text
    assert "mode (default: \"fast\") A module parameter: a string. a mode" \
        in text


@pytest.mark.parametrize("troff,rst", [
    (r"a\fBb\fRc", r"a\ **b**\ c"),
    (r"\fB a \fR b", r"**a** b"),
    (r"x \fIy\fP z", r"x *y* z"),
    (r"x \fIy\fP.", r"x *y*."),
    (r"(\fBq\fR)", r"\(**q**)"),
    ("* star _under_ `tick` |pipe|", r"\* star \_under\_ \`tick\` \|pipe\|"),
    (r"back\e slash \- minus \(bu", "back\\\\ slash - minus \u2022"),
    ("- dash", r"\- dash"),
    ("2. two", r"\2. two"),
    ("see::", r"see:\:"),
    (r"\&.. not a comment", r"\.. not a comment"),
])
def test_troff_to_rst_inline(troff: str, rst: str) -> None:
    from halcompile.gen_doc import troff_to_rst
    assert troff_to_rst(troff) == [rst]


def test_troff_to_rst_blocks() -> None:
    from halcompile.gen_doc import troff_to_rst
    text = ".PP\nfirst\nline\n.IP \\(bu\nitem\n.nf\n  a\nb\n.fi\n.B bold"
    assert troff_to_rst(text) == [
        "first line", "", "- item", "", ".. code-block:: none", "",
        "     a", "   b", "", "**bold**"]
    assert troff_to_rst(".TP\n.B tag\nbody", "  ") == [
        "  **tag**", "     body"]
    assert troff_to_rst(None) == [] and troff_to_rst("") == []


# ------------------------------------------------------------------ API


def test_document_writes_the_formats_asked(tmp_path, rich: str) -> None:
    out = tmp_path / "new" / "folder"
    assert document(rich, str(out), ("rst",)) == [str(out / "hcdocs.rst")]
    assert sorted(os.listdir(out)) == ["hcdocs.rst"]
    assert (out / "hcdocs.rst").read_text() == rst_page(parse_file(rich))
    assert document(rich, str(out), ("man",)) == [str(out / "hcdocs.9")]
    assert (out / "hcdocs.9").read_text() == man_page(parse_file(rich))
    with pytest.raises(ValueError, match="pdf"):
        document(rich, str(out), ("pdf",))
    with pytest.raises(CompError):
        document(os.path.join(COMPS, "hcbadsyntax.comp"), str(out))
    assert sorted(os.listdir(out)) == ["hcdocs.9", "hcdocs.rst"]


def test_install_doc_puts_the_page_where_man_finds_it(
        tmp_path, monkeypatch, rich: str) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    path = install_doc(rich)
    assert path == str(tmp_path / "data" / "man" / "man9" / "hcdocs.9")
    assert open(path).read() == man_page(parse_file(rich))
    if MAN is not None:
        proc = subprocess.run([MAN, "-M", str(tmp_path / "data" / "man"),
                               "-w", "9", "hcdocs"], capture_output=True,
                              text=True)
        assert proc.stdout.strip() == path, proc.stderr
    other = install_doc(rich, str(tmp_path / "elsewhere"))
    assert other == str(tmp_path / "elsewhere" / "man9" / "hcdocs.9")
    user = install_doc(os.path.join(COMPS, "hcuser.comp"))
    assert user == str(tmp_path / "data" / "man" / "man1" / "hcuser.1")
    assert file_name(parse_file(os.path.join(COMPS, "hcuser.comp")),
                     "man") == "hcuser.1"


@needs_man
def test_view_doc_renders_with_man(tmp_path, rich: str) -> None:
    code = ("import sys; from halcompile.gen_doc import view_doc; "
            "sys.exit(view_doc(sys.argv[1]))")
    env = dict(os.environ, MANWIDTH="80", MANPAGER="cat", PAGER="cat")
    proc = subprocess.run([sys.executable, "-c", code, rich],
                          capture_output=True, text=True, env=env,
                          cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert re.search(r"^HCDOCS\(9\) +HAL Component +HCDOCS\(9\)$",
                     proc.stdout, re.M)
    assert "hcdocs.N.gain float rw" in squash(proc.stdout)
    assert not os.listdir(tmp_path)


def test_view_doc_prints_the_text_without_man(monkeypatch, capsys,
                                              rich: str) -> None:
    monkeypatch.setattr(gen_doc.shutil, "which", lambda name: None)
    assert gen_doc.view_doc(rich) == 0
    out = capsys.readouterr().out
    assert out == man_page(parse_file(rich))


# ------------------------------------------------------------------ command

def _cli_wired() -> bool:
    from halcompile import cli
    return hasattr(cli, "_document")


needs_cli = pytest.mark.skipif(not _cli_wired(),
                               reason="halcompile.cli does not document yet")


@needs_cli
def test_command_document_and_install_doc(tmp_path, monkeypatch, capsys,
                                          rich: str) -> None:
    from halcompile.cli import main
    monkeypatch.chdir(tmp_path)
    hcuser = os.path.join(COMPS, "hcuser.comp")
    assert main(["--document", rich, hcuser]) == 0
    assert sorted(os.listdir(tmp_path)) == ["hcdocs.9", "hcdocs.rst",
                                            "hcuser.1", "hcuser.rst"]
    assert capsys.readouterr().out.split() == [
        str(tmp_path / n) for n in ("hcdocs.9", "hcdocs.rst", "hcuser.1",
                                    "hcuser.rst")]
    assert (tmp_path / "hcdocs.9").read_text() == man_page(parse_file(rich))
    assert main(["--document", "-o", "sub", rich]) == 0
    assert sorted(os.listdir(tmp_path / "sub")) == ["hcdocs.9", "hcdocs.rst"]
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    capsys.readouterr()
    assert main(["--install-doc", rich]) == 0
    page = tmp_path / "data" / "man" / "man9" / "hcdocs.9"
    assert capsys.readouterr().out.strip() == str(page)
    assert page.read_text() == man_page(parse_file(rich))


@needs_cli
def test_command_document_errors(tmp_path, monkeypatch, capsys) -> None:
    from halcompile.cli import main
    monkeypatch.chdir(tmp_path)
    assert main(["--document", "nothere.comp"]) == 1
    assert "halcompile: nothere.comp: no such file" in capsys.readouterr().err
    (tmp_path / "prog.c").write_text("int main(void) { return 0; }\n")
    assert main(["--view-doc", "prog.c"]) == 1
    assert "only .comp files" in capsys.readouterr().err
    assert main(["--document", os.path.join(COMPS, "hcbadsyntax.comp")]) == 1
    err = capsys.readouterr().err
    assert "hcbadsyntax.comp:3:9: expected a HAL type" in err
    assert "Traceback" not in err
    assert sorted(os.listdir(tmp_path)) == ["prog.c"]


@needs_cli
@needs_man
def test_command_view_doc(tmp_path, rich: str) -> None:
    env = dict(os.environ, MANWIDTH="80", MANPAGER="cat", PAGER="cat")
    proc = subprocess.run([sys.executable, "-m", "halcompile", "--view-doc",
                           rich], capture_output=True, text=True, env=env,
                          cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert "hcdocs.N.gain float rw (default: 1.0)" in proc.stdout
    assert not os.listdir(tmp_path)
