"""The panels: the CLI's commands run on the page's model, with the CLI's options as a form.

`form(parser)` describes a command's argparse parser as fields the page draws (a flag, a choice, a
number or text, a file to read, a file to write, the model in the editor; a sub-command switches the
fields: `synth function|motion|path|seed001`). `argv(fields, values, files)` turns what the page sends
back into the command's arguments ({dest: text}, a flag by its option string: {"--json": true}), every file
checked against the served folder. `Run` runs
``python -m mbplanar COMMAND ...`` in a process of its own, in a temporary folder holding the model as the
editor has it: the page gets the CLI's own output and messages, the progress the command writes on its
standard error line by line, and the files it wrote (pictures shown, models opened, tables downloaded);
cancel sends it Ctrl-C (SIGINT) and, if it is still running 5 s later, ends it.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import re
import signal
import sys
from pathlib import Path

from ._files import Refused

__all__ = ["PANELS", "EXPORTS", "form", "argv", "Run"]

#: the panels, in the page's order
PANELS = ("info", "check", "forces", "dynamics", "cam", "study", "accuracy", "synth", "simulate", "balance")
#: the exports of the file menu: the command each runs and the options the page fills in
EXPORTS = ("report", "animate", "sweep", "plot")
#: options whose value is a file the command reads (positional `model`/`file` is the editor's model), and
#: the command they are a file of where another command's option of that name is not (`sweep --from` is a value)
READS = {"variants": None, "start": "simulate", "input": None, "model": None}
#: options whose value is a file the command writes, with the file's default name
WRITES = {"output": "{model}.{ext}", "dxf": "profile.dxf", "svg": "profile.svg", "plot_output": "picture.png",
          "curve": "curves.csv"}
OUTPUT_EXT = {"sweep": "csv", "dynamics": "csv", "simulate": "csv", "cam": "csv", "synth": "toml",
              "study": "csv", "accuracy": "csv", "report": "html", "animate": "html", "plot": "png"}
CANCEL_GRACE = 5.0        # seconds between Ctrl-C and the end of a cancelled run


def form(parser: argparse.ArgumentParser, command: str) -> list[dict]:
    """The fields of `command`'s options in the parser of `mbplanar COMMAND` (see the module docstring)."""
    sub = _subparser(parser, command)
    return _fields(sub, command) if sub is not None else []


def _subparser(parser, name):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action.choices.get(name)
    return None


def _fields(parser, command) -> list[dict]:
    out = []
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        if isinstance(action, argparse._SubParsersAction):
            out.append({"dest": action.dest, "kind": "sub", "help": "",
                        "choices": {name: {"help": _help_of(action, name), "fields": _fields(p, command)}
                                    for name, p in action.choices.items()}})
            continue
        flags = [s for s in action.option_strings if s.startswith("--")] or action.option_strings
        field = {"dest": action.dest, "flag": flags[0] if flags else None, "help": action.help or "",
                 "required": bool(action.required) or not action.option_strings,
                 "default": action.default if isinstance(action.default, (str, int, float, bool)) else None,
                 "metavar": action.metavar if isinstance(action.metavar, str) else None}
        if isinstance(action, (argparse._StoreTrueAction, argparse._StoreFalseAction)):
            field["kind"] = "flag"
            field["default"] = bool(action.default) if isinstance(action, argparse._StoreTrueAction) else None
            field["store"] = isinstance(action, argparse._StoreTrueAction)
        elif not action.option_strings and action.dest in ("model", "file"):
            field["kind"] = "model"
        elif action.dest in WRITES or (action.dest == "plot" and not action.choices):
            field["kind"] = "write"
            name = WRITES.get(action.dest, "picture.png")
            field["default"] = name.format(model="{model}", ext=OUTPUT_EXT.get(command, "csv"))
        elif action.dest in READS and READS[action.dest] in (None, command):
            field["kind"] = "read"
        elif action.choices:
            field["kind"], field["choices"] = "choice", [str(c) for c in action.choices]
        else:
            field["kind"] = "number" if action.type in (int, float) else "text"
        field["append"] = isinstance(action, argparse._AppendAction)
        out.append(field)
    return out


def _help_of(action, name) -> str:
    for choice in action._choices_actions:
        if choice.dest == name:
            return choice.help or ""
    return ""


def argv(fields: list[dict], values: dict, files) -> list[str]:
    """The command's arguments from the page's `values` ({dest: text}, {"--flag": bool}). `files` maps a file to
    read or write to the path the run uses: files.model() (the editor's model), files.read(name),
    files.write(name)."""
    out, later = [], []
    if not isinstance(values, dict):
        raise Refused("a run's values are a table of option names", 400)
    for field in fields:
        dest, kind = field["dest"], field["kind"]
        value = values.get(dest)
        if kind == "sub":
            choice = str(value or "")
            if choice not in field["choices"]:
                raise Refused(f"choose one of {', '.join(field['choices'])}", 400)
            out.append(choice)
            out += argv(field["choices"][choice]["fields"], values, files)
            continue
        if kind == "flag":                 # by its own option string: --progress and --no-progress share a dest
            if _true(values.get(field["flag"])):
                out.append(field["flag"])
            continue
        if kind == "model":
            out.append(files.model())
            continue
        texts = _texts(value, field.get("append"))
        if not texts:
            if field.get("required") and field["flag"] is None:
                raise Refused(f"{dest}: a value is needed", 400)
            continue
        for text in texts:
            if kind == "read":
                text = files.read(text)
            elif kind == "write":
                text = files.write(text)
            if field["flag"] is None:
                later.append(text)
            else:
                out += [field["flag"], text]
    return _positional_first(out, later)


def _positional_first(options, positionals):
    """Positional values go first (argparse reads them anywhere, but a value such as '-5' could pass for an
    option there): after the sub-command's name when there is one."""
    return positionals + options if not options or options[0].startswith("-") else \
        options[:1] + positionals + options[1:]


def _true(value) -> bool:
    return value is True or str(value).lower() in ("1", "true", "on", "yes")


def _texts(value, append) -> list[str]:
    if value is None or value is False:
        return []
    if isinstance(value, list):
        items = [str(v) for v in value]
    elif append:
        items = str(value).splitlines()
    else:
        items = [str(value)]
    return [t.strip() for t in items if t.strip()]


class Run:
    """One command of the CLI in a process of its own (see the module docstring).

    Parameters
    ----------
    args : list of str
        The command and its arguments (after ``mbplanar``).
    folder : Path
        Its working folder (the model's copy and the files it writes).
    on_line : callable
        Awaited with each line the command writes on its standard error, as it comes.
    """

    def __init__(self, args, folder: Path, on_line):
        self.args, self.folder, self.on_line = list(args), Path(folder), on_line
        self.process, self.cancelled = None, False

    async def run(self) -> dict:
        """{"code", "stdout", "stderr", "cancelled"} once the command has ended."""
        env = dict(os.environ, PYTHONUNBUFFERED="1", COLUMNS="120")
        before = set(self.folder.iterdir())
        self.process = await asyncio.create_subprocess_exec(
            sys.executable, "-m", "mbplanar", *self.args, cwd=str(self.folder), env=env,
            stdin=asyncio.subprocess.DEVNULL, stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE,
            start_new_session=True)
        out_task = asyncio.ensure_future(self.process.stdout.read())
        err = await self._lines(self.process.stderr)
        out = await out_task
        code = await self.process.wait()
        made = sorted(p for p in set(self.folder.iterdir()) - before if p.is_file())
        return {"code": code, "stdout": out.decode("utf-8", "replace"), "stderr": err,
                "cancelled": self.cancelled, "files": made}

    async def _lines(self, stream) -> str:
        """Standard error, passed on line by line (a progress bar's carriage returns end a line too)."""
        seen, pending = [], b""
        while True:
            chunk = await stream.read(4096)
            if not chunk:
                break
            pending += chunk
            *lines, pending = re.split(rb"\r\n|\r|\n", pending)
            for line in lines:
                text = line.decode("utf-8", "replace")
                if text.strip():
                    seen.append(text)
                    await self.on_line(text)
        if pending.strip():
            seen.append(pending.decode("utf-8", "replace"))
            await self.on_line(seen[-1])
        return "\n".join(_final_lines(seen))

    async def cancel(self):
        """Ctrl-C, then the end of the process if it is still running after `CANCEL_GRACE` seconds."""
        process = self.process
        if process is None or process.returncode is not None:
            return
        self.cancelled = True
        try:
            process.send_signal(signal.SIGINT)
            await asyncio.wait_for(process.wait(), CANCEL_GRACE)
        except asyncio.TimeoutError:
            process.kill()
        except ProcessLookupError:
            pass

    def kill(self):
        if self.process is not None and self.process.returncode is None:
            try:
                self.process.kill()
            except ProcessLookupError:
                pass


def _final_lines(lines: list[str]) -> list[str]:
    """The lines of standard error without a progress bar's intermediate states (a line that the next one
    redraws: the same text up to its counts)."""
    out = []
    for line in lines:
        if out and _bar(out[-1]) and _bar(line) == _bar(out[-1]):
            out[-1] = line
        else:
            out.append(line)
    return out


def _bar(line: str) -> str:
    return re.sub(r"[\d.:,/%|#█▏▎▍▌▋▊▉ ]+", " ", line).strip() if "%" in line or "|" in line else ""
