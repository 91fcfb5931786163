"""The documentation every FMU carries: ``documentation/index.html``, FMI 2.0's entry point.

``render_documentation`` writes one self-contained HTML5 page (inline CSS, no scripts, no
external resources) from what the project already states once: the component's docstrings
(which cite the source documents), its VARIABLES and PORTS tables, its regime names, and
the FMU's record (``fmus.registry``): the wrapper script's description and default
experiment, the requirements, and the example scenes that couple the FMU (named, never
read: an FMU depends on no scene file).  The page tells a user of another tool (FMPy,
libcosim, a C/C++ master) what the FMU models, how to couple it, and what its host needs.
"""

from __future__ import annotations

import inspect
import re
import shlex
import sys
import textwrap
from html import escape

from components.base import COMMON_OUTPUTS, Component
from fmus.description import EVENT_TIME, INDICATOR_PREFIX, REGIME
from fmus.host_loader import RUNTIME_FILE, loader_binary, newest_version_needed, runtime_binary
from fmus.input_derivatives import ramped_inputs
from fmus.ports import PORT_RULE
from fmus.registry import FmuRecord

#: Outputs every component shares (energy bookkeeping): poor examples of what one computes.
_COMMON = {v.name for v in COMMON_OUTPUTS} | {"external_work"}
SAMPLED_NOTE = (
    "sampled: the value is taken as a state at the start of each step, not a signal held "
    "over the step; a master should not average it"
)


# -- public entry point ---------------------------------------------------------------------
def render_documentation(record: FmuRecord, loader: bool = True) -> str:
    """The FMU's ``documentation/index.html``: a complete, standalone HTML5 page.
    ``loader``: the FMU's Linux binary is the loader (``fmus.host_loader``) that lets hosts
    without Python run it, not pythonfmu's runtime alone."""
    component_class = record.component_class
    description = record.description.rstrip(".")
    title = f"{record.name}: FMU documentation"
    sections = [
        ("model", "What it models", _model_section(record, description)),
        ("ports", "Ports", _ports_section(component_class)),
        ("variables", "Variables", _variables_section(component_class)),
        ("regimes", "Regimes and events", _regimes_section(record)),
        ("coupling", "How to couple it", _coupling_section(record)),
        ("host", "Host requirements", _host_section(record, loader)),
        ("tools", "Usage in other tools", _tools_section(record)),
        ("capabilities", "FMI capabilities", _capabilities_section(record, loader)),
    ]
    toc = "".join(f'<li><a href="#{key}">{escape(head)}</a></li>' for key, head, _ in sections)
    body = "".join(
        f'<section id="{key}">\n<h2>{escape(head)}</h2>\n{html}</section>\n'
        for key, head, html in sections
    )
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{escape(title)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
        f"<header>\n<h1>{escape(record.name)}</h1>\n"
        f'<p class="lead">{escape(description)}</p>\n'
        "<dl>"
        f"<dt>Model identifier</dt><dd><code>{escape(record.name)}</code></dd>"
        "<dt>Standard</dt><dd>FMI 2.0, co-simulation</dd>"
        f"<dt>Component</dt><dd><code>{escape(record.component)}</code> "
        "(plain Python, wrapped by a generic pythonfmu slave)</dd>"
        "</dl>\n</header>\n"
        f'<nav>\n<h2>Contents</h2>\n<ol class="toc">{toc}</ol>\n</nav>\n'
        f"<main>\n{body}</main>\n"
        "<footer><p>Generated at build time from the component's declarations, docstrings "
        "and the example scenes' connections.</p></footer>\n"
        "</body>\n</html>\n"
    )


# -- docstrings as HTML -----------------------------------------------------------------------
_BULLET = re.compile(r"^(?:([*-])|(\d+)\.)\s+(.*)$")
_LITERAL = re.compile(r"``(.+?)``|`([^`\s][^`]*?)`")
_EMPHASIS = re.compile(r"(?<![\w*])\*([A-Za-z](?:[A-Za-z -]*[A-Za-z])?)\*(?![\w*])")


def _inline(text: str) -> str:
    """Escape ``text``; ``literals`` become code, *words* emphasis (reST-like docstrings)."""
    out, last = [], 0
    for m in _LITERAL.finditer(text):
        out.append(_EMPHASIS.sub(r"<em>\1</em>", escape(text[last : m.start()])))
        out.append(f"<code>{escape(m.group(1) or m.group(2))}</code>")
        last = m.end()
    out.append(_EMPHASIS.sub(r"<em>\1</em>", escape(text[last:])))
    return "".join(out)


def docstring_html(doc: str | None) -> str:
    """A docstring as paragraphs, bullet or numbered lists and preformatted blocks.

    Indented lines that do not continue a list item are equations or tables: they keep
    their layout in a ``<pre>``.
    """
    text = inspect.cleandoc(doc or "")
    html: list[str] = []
    for block in re.split(r"\n[ \t]*\n", text):
        html.extend(_block_html(block.splitlines()))
    return "\n".join(html) + "\n" if html else ""


def _block_html(lines: list[str]) -> list[str]:
    out: list[str] = []
    para: list[str] = []
    pre: list[str] = []
    items: list[tuple[str | None, str]] = []  # (number, text); number None: a bullet
    numbered = False

    def flush() -> None:
        nonlocal numbered
        if para:
            out.append(f"<p>{_inline(' '.join(para))}</p>")
            para.clear()
        if pre:
            out.append(f"<pre>{escape(textwrap.dedent(chr(10).join(pre)))}</pre>")
            pre.clear()
        if items:
            tag = "ol" if numbered else "ul"
            lis = "".join(
                f'<li value="{n}">{_inline(t)}</li>' if n is not None else f"<li>{_inline(t)}</li>"
                for n, t in items
            )
            out.append(f"<{tag}>{lis}</{tag}>")
            items.clear()
            numbered = False

    for line in lines:
        indent = len(line) - len(line.lstrip())
        bullet = _BULLET.match(line) if indent == 0 else None
        if bullet:
            if para or pre or (items and numbered != (bullet.group(2) is not None)):
                flush()
            numbered = bullet.group(2) is not None
            items.append((bullet.group(2), bullet.group(3).strip()))
        elif indent > 0 and items and not pre:
            number, item = items[-1]
            items[-1] = (number, f"{item} {line.strip()}")
        elif indent > 0:
            if para or items:
                flush()
            pre.append(line)
        else:
            if pre or items:
                flush()
            para.append(line.strip())
    flush()
    return out


# -- sections -----------------------------------------------------------------------------------
def _model_section(record: FmuRecord, description: str) -> str:
    cls = record.component_class
    module = sys.modules[cls.__module__]
    return (
        f"<p><strong>{escape(record.name)}</strong>: {escape(description)}.</p>\n"
        "<p>The sources (reports, equations, tables, pages) are cited in the component's own "
        "documentation, reproduced here.</p>\n"
        f"<h3>Module <code>{escape(cls.__module__)}</code></h3>\n"
        f'<div class="doc">\n{docstring_html(module.__doc__)}</div>\n'
        f"<h3>Class <code>{escape(cls.__name__)}</code></h3>\n"
        f'<div class="doc">\n{docstring_html(cls.__doc__)}</div>\n'
    )


def _ports_section(cls: type[Component]) -> str:
    if not cls.PORTS:
        return (
            "<p>This FMU has no rotational ports: connect its variables one by one "
            '(see <a href="#variables">Variables</a>).</p>\n'
        )
    parts = [
        "<p>A port groups the variables of one shaft or joint by <em>role</em> (angle, "
        "speed, torque, and extra roles some joints need). "
        f"{escape(PORT_RULE)}</p>\n"
    ]
    for port, roles in cls.PORTS.items():
        rows = []
        for role, name in roles.items():
            var = cls.variable(name)
            direction = {"output": "out", "input": "in"}.get(var.causality, var.causality)
            note = f' <span class="tag">{escape(SAMPLED_NOTE)}</span>' if var.sampled else ""
            rows.append(
                '<tr class="role">'
                f"<td><code>{escape(role)}</code></td><td><code>{escape(name)}</code></td>"
                f"<td>{escape(var.causality)} ({direction})</td><td>{escape(var.type)}</td>"
                f"<td>{escape(var.unit)}</td><td>{escape(var.description)}{note}</td></tr>"
            )
        parts.append(
            f"<h3>Port <code>{escape(port)}</code></h3>\n"
            f'<table id="port-{escape(port)}">\n'
            "<thead><tr><th>role</th><th>variable</th><th>causality (direction)</th>"
            "<th>type</th><th>unit</th><th>description</th></tr></thead>\n"
            f"<tbody>\n{chr(10).join(rows)}\n</tbody>\n</table>\n"
        )
    return "".join(parts)


def _variables_section(cls: type[Component]) -> str:
    names = getattr(cls, "REGIME_NAMES", {})
    rows = []
    for var in cls.VARIABLES:
        notes = []
        if var.causality == "input" and var.sampled:
            notes.append(f'<span class="tag">{escape(SAMPLED_NOTE)}</span>')
        if var.causality == "output":
            deps = ", ".join(f"<code>{escape(d)}</code>" for d in var.depends_on) or "none"
            notes.append(f"direct feedthrough from: {deps}")
        if var.role is not None:  # carried in the vendor annotation (fmus/description.py)
            notes.append(f"coupling role: <code>{escape(str(var.role))}</code>")
        vtype = "Enumeration" if var.name == REGIME and names else var.type
        rows.append(
            f'<tr class="variable" id="var-{escape(var.name)}">'
            f"<td><code>{escape(var.name)}</code></td><td>{escape(var.causality)}</td>"
            f"<td>{vtype}</td><td>{escape(var.unit)}</td>"
            f'<td class="num">{escape(_number(var.start, var.type))}</td>'
            f'<td class="num">{escape(_number(var.min, var.type))}</td>'
            f'<td class="num">{escape(_number(var.max, var.type))}</td>'
            f"<td>{escape(var.description)}</td><td>{'<br>'.join(notes)}</td></tr>"
        )
    n = {c: sum(v.causality == c for v in cls.VARIABLES) for c in ("parameter", "input", "output")}
    return (
        f"<p>{n['parameter']} parameters, {n['input']} inputs, {n['output']} outputs, in the "
        "order of the model description. Values are SI in the unit shown (an FMI unit name; "
        "<code>1</code>: dimensionless or a count). Min and max are blank where there is "
        "no bound.</p>\n"
        "<ul>\n"
        f"<li><em>Sampled</em> inputs: {escape(SAMPLED_NOTE)}. Other inputs are signals "
        "held constant over a step (zero-order hold).</li>\n"
        "<li><em>Direct feedthrough</em>: the inputs an output depends on within one instant "
        "(set an input, read the output, no step between); <em>none</em>: the output "
        "changes only by stepping, so it never closes an algebraic loop.</li>\n"
        "</ul>\n"
        '<table id="variables-table">\n'
        "<thead><tr><th>name</th><th>causality</th><th>type</th><th>unit</th><th>start</th>"
        "<th>min</th><th>max</th><th>description</th><th>notes</th></tr></thead>\n"
        f"<tbody>\n{chr(10).join(rows)}\n</tbody>\n</table>\n"
    )


def _regimes_section(record: FmuRecord) -> str:
    cls = record.component_class
    names: dict[int, str] = getattr(cls, "REGIME_NAMES", {})
    outputs = cls.variables("output")
    parts = []
    if names:
        rows = "".join(
            f'<tr class="regime"><td class="num">{code}</td><td>{escape(name)}</td></tr>'
            for code, name in sorted(names.items())
        )
        parts.append(
            f"<p>The output <code>{REGIME}</code> gives the regime (mode) the component is "
            "in. In the model description it is an Enumeration (type "
            f"<code>{escape(record.name)}.Regime</code>) whose items are these names; read "
            "it as an Integer (fmi2GetInteger).</p>\n"
            '<table id="regimes">\n<thead><tr><th>code</th><th>regime</th></tr></thead>\n'
            f"<tbody>{rows}</tbody>\n</table>\n"
        )
    elif any(v.name == REGIME for v in outputs):
        parts.append(
            f"<p>The output <code>{REGIME}</code> is an Integer; this component names no "
            "regimes (it has one mode).</p>\n"
        )
    indicators = [v for v in outputs if v.name.startswith(INDICATOR_PREFIX)]
    if indicators:
        items = "".join(
            f'<li class="indicator"><code>{escape(v.name)}</code> [{escape(v.unit)}]: '
            f"{escape(v.description)}</li>"
            for v in indicators
        )
        parts.append(
            "<p>Event indicators (outputs named <code>ind_*</code>): a regime switch happens "
            "where one crosses zero. A master that steps past a switch sees the sign change "
            f"and can locate it.</p>\n<ul>{items}</ul>\n"
        )
    else:
        parts.append("<p>This FMU declares no event indicator outputs (<code>ind_*</code>).</p>\n")
    event = next((v for v in outputs if v.name == EVENT_TIME), None)
    if event is not None:
        parts.append(
            f"<p><code>{EVENT_TIME}</code> [s] ({escape(event.description)}): the time of the "
            "last internal event the FMU located inside a step (start value "
            f"{escape(_number(event.start, event.type))}: none yet), so that a master can "
            "land on it: restore the state saved at the step start (fmi2SetFMUstate) and "
            f"retake the step with length <code>{EVENT_TIME} - t</code>.</p>\n"
        )
    return "".join(parts)


def _coupling_section(record: FmuRecord) -> str:
    rule = (
        '<p>Ports connect by the rule of <a href="#ports">Ports</a>; a single signal '
        "connects one output to one input of the same type and unit (each input driven by "
        "one output at most).</p>\n"
    )
    if not record.example_paths:
        return rule + (
            "<p>No scene of the project couples this FMU with another FMU (the scenes that "
            "use it run it alone): drive its inputs from any outputs of the same type and "
            'unit, or set them as start values (see <a href="#tools">Usage in other '
            "tools</a>).</p>\n"
        )
    scenes = "".join(f"<li><code>{escape(path)}</code></li>" for path in record.example_paths)
    return rule + (
        "<p>Worked couplings of this FMU with others are the project's scenes below: each "
        "names its FMUs in <code>[fmus.&lt;instance&gt;]</code> tables and joins them in "
        "<code>[[connections]]</code> (ports by the rule above, single signals as "
        "<code>from</code> / <code>to</code>); <code>mechcosim export</code> spells "
        "a scene out variable by variable for another tool. The values each scene sets are "
        "in its file: a value with a unit is converted to the SI unit of the variables table "
        "before it is set on the FMU; a bare number is already SI.</p>\n"
        f'<ul class="examples">{scenes}</ul>\n'
    )


def _host_section(record: FmuRecord, loader: bool) -> str:
    requirements = record.requirements()
    if requirements:
        reqs = "".join(f"<li><code>{escape(r)}</code></li>" for r in requirements)
        reqs = f"<ul>{reqs}</ul>\n"
        install = " ".join(shlex.quote(r) for r in requirements)
        install_cmd = f"python3 -m pip install {install}"
    else:
        reqs = "<p>No packages beyond the standard library.</p>\n"
        install_cmd = ""
    fmu = f"{record.name}.fmu"
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    if loader:
        other_hosts = (
            "<li><strong>Other hosts on Linux</strong> (libcosim's <code>cosim</code> command "
            "line, the FMI Compliance Checker, OMSimulator, a C/C++ tool): nothing to set up "
            "on the machine that built the FMU, no <code>LD_PRELOAD</code>, no "
            "<code>PYTHONPATH</code>. The FMU's binary is a small loader: where the host "
            "process has no Python, it loads the Python that built the FMU (named in "
            "<code>resources/python.txt</code>: its executable and its shared libpython), "
            "starts it as that executable starts (a virtual environment's packages "
            "included) and runs the FMU's code in it. Elsewhere, name a Python "
            f"{escape(version)} that has the packages:"
            f"<pre>MECHCOSIM_PYTHON=/path/to/venv/bin/python</pre>"
            "Its libpython is looked for in the <code>lib/</code> of its base installation, "
            "then on the system's library path; or write both lines "
            "(<code>executable=</code>, <code>library=</code>) into "
            "<code>resources/python.txt</code> inside the FMU. The first FMU that starts "
            "Python in a process starts it for all.</li>\n"
        )
        binaries = [b for b in (loader_binary(record.name), runtime_binary()) if b]
        glibc = newest_version_needed(binaries, b"GLIBC_")
        cxx = newest_version_needed(binaries, b"GLIBCXX_")
        other_hosts += (
            "<li><strong>What the Linux binaries need</strong> (x86-64): the loader "
            f"<code>binaries/linux64/{escape(record.name)}.so</code> needs glibc "
            f"{escape(glibc or '?')} or later and a Python {escape(version)} (exactly: it "
            "starts that version's interpreter, and refuses at fmi2Instantiate anything "
            "else named by <code>MECHCOSIM_PYTHON</code>); pythonfmu's runtime beside it, "
            f"<code>{RUNTIME_FILE}</code>, needs libstdc++ with GLIBCXX_{escape(cxx or '?')} "
            "and libgcc_s.</li>\n"
        )
        errors = (
            "<li>Whatever the FMU logs with a status other than fmi2OK reaches the host's "
            "logger with debug logging off too. A missing package, or a Python that cannot "
            "be found or started, makes <code>fmi2Instantiate</code> return NULL with the "
            "reason logged (fmi2Error or fmi2Fatal).</li>\n"
        )
    else:
        other_hosts = (
            "<li><strong>Other hosts</strong>: this build's Linux binary is pythonfmu's "
            "runtime alone (no C compiler where it was built), which does not link libpython: "
            "it loads only in a process that has Python already. Build the FMU where a C "
            "compiler is found to get the binary that loads in any host.</li>\n"
        )
        errors = (
            "<li>A missing module is reported when the FMU is instantiated, on standard "
            "error; the FMU's log reaches the host only with debug logging on.</li>\n"
        )
    return (
        "<p>The FMU's code is Python, run by pythonfmu's runtime (the code is packed in "
        "<code>resources/</code>). It needs <strong>Python 3.11 or later</strong> with these "
        "packages:</p>\n"
        f"{reqs}"
        + (f"<pre>{escape(install_cmd)}</pre>\n" if install_cmd else "")
        + "<p>The same list is packed as <code>resources/requirements.txt</code>; "
        f"<code>pythonfmu deploy -f {escape(fmu)}</code>, run with that Python, installs "
        "it.</p>\n"
        "<ul>\n"
        "<li><strong>Python hosts</strong> (FMPy, libcosimpy, a Python master): the FMU "
        "runs in the host's own interpreter, whether its executable links libpython or has "
        "it built in; install the packages into that same environment.</li>\n"
        f"{other_hosts}{errors}"
        "</ul>\n"
    )


def _tools_section(record: FmuRecord) -> str:
    cls = record.component_class
    fmu = f"{record.name}.fmu"
    start, stop, step = record.default_run
    params = cls.variables("parameter")[:2]
    # The first output of the component's own (the energy outputs every component shares
    # say little about it), and the regime.
    own = [v.name for v in cls.variables("output") if v.name not in _COMMON]
    outputs = own[:1] + [REGIME] if any(v.name == REGIME for v in cls.VARIABLES) else own[:2]
    start_values = " ".join(f"{v.name} {_number(v.start, v.type)}" for v in params)
    sv_opt = f" --start-values {start_values}" if params else ""
    simulate = (
        f"fmpy simulate {fmu}{sv_opt} --start-time {_g(start)} --stop-time {_g(stop)} "
        f"--step-size {_g(step)} --output-variables {' '.join(outputs)} "
        f"--output-file {record.name}.csv"
    )
    py_values = ", ".join(f'"{v.name}": {_number(v.start, v.type)}' for v in params)
    out_list = ", ".join(f'"{o}"' for o in outputs)
    snippet = "\n".join(
        [
            "from fmpy import simulate_fmu",
            f"start_values = {{{py_values}}}  # SI units of the variables table",
            f'result = simulate_fmu("{fmu}", start_time={_g(start)}, stop_time={_g(stop)}, '
            f"step_size={_g(step)},",
            f"                      start_values=start_values, output=[{out_list}])",
            "for name in result.dtype.names:",
            "    print(name, result[name][-1])",
        ]
    )
    cosim_values = " ".join(f"{v.name}={_number(v.start, v.type)}" for v in params)
    cosim = (
        f"cosim run-single {fmu} {cosim_values} "
        f"-b {_g(start)} -d {_g(stop - start)} -s {_g(step)} --output-file {record.name}.csv"
    )
    libcosim = "\n".join(
        [
            "from libcosimpy.CosimExecution import CosimExecution",
            "from libcosimpy.CosimSlave import CosimLocalSlave",
            "",
            f"execution = CosimExecution.from_step_size(step_size={round(step * 1e9)})  # ns",
            f'index = execution.add_local_slave(CosimLocalSlave(fmu_path="{fmu}", '
            f'instance_name="{record.name.lower()}"))',
            "vr = {v.name.decode(): v.reference for v in execution.slave_variables(index)}",
            "# per connection: connect_real_variables(out_index, out_vr, in_index, in_vr),",
            "# connect_integer_variables(...) for an Integer connection",
            f"execution.simulate_until(target_time={round((stop - start) * 1e9)})  # ns",
        ]
    )
    return (
        f"<p>Below, <code>{escape(fmu)}</code> is the FMU file. Run alone, the FMU uses "
        f"its default experiment: start {_g(start)} s, stop {_g(stop)} s, step "
        f"{_g(step)} s. Start values are SI (variables table); any parameter or input can "
        "be set by name.</p>\n"
        "<h3>FMPy</h3>\n"
        f"<pre>fmpy info {escape(fmu)}\nfmpy validate {escape(fmu)}\n{escape(simulate)}</pre>\n"
        "<p>From Python:</p>\n"
        f"<pre>{escape(snippet)}</pre>\n"
        "<h3>libcosim</h3>\n"
        "<p>libcosimpy (a Python host) adds each FMU with "
        "<code>CosimExecution.from_step_size</code> (step in integer nanoseconds) and "
        "<code>add_local_slave</code>, finds value references by name through "
        "<code>slave_variables</code>, and joins the connections of "
        '<a href="#coupling">How to couple it</a> with '
        "<code>connect_real_variables</code>, or <code>connect_integer_variables</code> for "
        "the Integer ones. Run each execution in a process of its own: libcosim unloads the "
        "FMU binary when it is done, and pythonfmu's runtime cannot be loaded again in the "
        "same process.</p>\n"
        f"<pre>{escape(libcosim)}</pre>\n"
        "<p>The <code>cosim</code> command line (a non-Python host, see "
        '<a href="#host">Host requirements</a>):</p>\n'
        f"<pre>cosim inspect {escape(fmu)}\n{escape(cosim)}</pre>\n"
    )


def _input_derivatives(record: FmuRecord, loader: bool) -> str:
    """What the FMU does with its inputs over a step (fmus.input_derivatives)."""
    pairs = ramped_inputs(record.component_class) if loader else []
    if not pairs:
        return "inputs are held constant over a step (no input derivatives or interpolation)"
    names = ", ".join(
        f"<code>{escape(u)}</code> (what the input <code>{escape(r)}</code> also sets)"
        for u, r in pairs
    )
    return (
        "<strong>canInterpolateInputs</strong>: fmi2SetRealInputDerivatives takes the first "
        f"derivative of {names}; the input then ramps from its value set at the step start, "
        "until the derivative is set again"
    )


def _capabilities_section(record: FmuRecord, loader: bool) -> str:
    return (
        "<ul>\n"
        "<li>FMI 2.0 <strong>co-simulation</strong> only (no model exchange); variable "
        f"communication step sizes; {_input_derivatives(record, loader)}.</li>\n"
        "<li><strong>canGetAndSetFMUstate</strong>: fmi2GetFMUstate saves the complete state, "
        "hidden variables and the regime included, so restoring it and stepping again "
        "reproduces the same numbers bit for bit; a state can be restored any number of "
        "times. The state cannot be serialized (canSerializeFMUstate is false).</li>\n"
        "<li>A step size that is not positive or not finite, a non-finite time, or a "
        "non-finite value set on a Real is rejected with <strong>fmi2Error</strong>, the "
        "reason in the FMU's log. A step the component cannot complete returns fmi2Error "
        "too, with the reason logged.</li>\n"
        "<li>Outputs are valid in initialization mode: a master may read them there to set "
        "consistent inputs.</li>\n"
        "</ul>\n"
    )


# -- formatting ---------------------------------------------------------------------------------
def _number(value: float | None, vtype: str) -> str:
    if value is None:
        return ""
    if vtype == "Integer":
        return str(int(value))
    return repr(float(value))


def _g(value: float) -> str:
    return repr(float(value))


_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; line-height: 1.45;
  max-width: 72rem; margin: 0 auto; padding: 1rem 1.5rem 3rem; color: #1b1f23; }
h1 { margin-bottom: 0.2rem; }
h2 { border-bottom: 1px solid #d0d7de; padding-bottom: 0.2rem; margin-top: 2rem; }
h3 { margin-top: 1.4rem; }
.lead { font-size: 1.15rem; color: #444; margin-top: 0; }
dl { display: grid; grid-template-columns: max-content auto; gap: 0.2rem 1rem; }
dt { font-weight: 600; }
dd { margin: 0; }
code, pre { font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, monospace;
  font-size: 0.9em; }
code { background: #f3f4f6; padding: 0 0.2em; border-radius: 3px; }
pre { background: #f6f8fa; border: 1px solid #d0d7de; border-radius: 4px; padding: 0.6rem;
  white-space: pre-wrap; overflow-wrap: anywhere; }
pre code { background: none; padding: 0; }
.doc { border-left: 3px solid #d0d7de; padding-left: 1rem; }
table { border-collapse: collapse; margin: 0.6rem 0 1rem; width: 100%; font-size: 0.92rem; }
th, td { border: 1px solid #d0d7de; padding: 0.25rem 0.5rem; text-align: left;
  vertical-align: top; }
th { background: #f6f8fa; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.integer td { background: #fff8e1; }
.tag { display: inline-block; font-size: 0.85em; color: #7a4b00; background: #fff4d6;
  border-radius: 3px; padding: 0 0.3em; }
.toc { columns: 2; }
footer { margin-top: 3rem; color: #666; font-size: 0.85rem; }
@media print { pre { white-space: pre-wrap; } nav { display: none; } }
"""
