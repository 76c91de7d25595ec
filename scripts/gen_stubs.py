#!/usr/bin/python3
"""Writes python/partsim/_partsim.pyi from the built extension's pybind11 docstrings.

pybind11-stubgen is not available here, so this reads the signatures pybind11 puts on the first
line of each docstring ("name(arg: type = default) -> type") and turns them into stub syntax:
numpy arrays become numpy.ndarray, defaults become `...`, overloads get @typing.overload.

Usage:
    /usr/bin/python3 scripts/gen_stubs.py [--python-dir build/python] [--check]

--check compares with the committed file instead of writing it (exit 1 when they differ).
"""

import argparse
import importlib
import inspect
import os
import re
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STUB = os.path.join(REPO, "python", "partsim", "_partsim.pyi")
MODULE = "partsim._partsim"

PYBIND_FUNC = type(len)  # builtin_function_or_method, what pybind11 functions look like
INSTANCE_METHOD = "instancemethod"


def _strip_brackets_after(text, prefix):
    """Removes the [...] that follows each `prefix` (bracket-aware)."""
    out, i = [], 0
    while True:
        j = text.find(prefix + "[", i)
        if j < 0:
            out.append(text[i:])
            return "".join(out)
        out.append(text[i:j + len(prefix)])
        k, depth = j + len(prefix), 0
        while k < len(text):
            if text[k] == "[":
                depth += 1
            elif text[k] == "]":
                depth -= 1
                if depth == 0:
                    break
            k += 1
        i = k + 1


def clean_type(t):
    """pybind11's docstring type -> stub type."""
    t = t.strip()
    t = _strip_brackets_after(t, "numpy.ndarray")
    t = t.replace(MODULE + ".", "")
    t = re.sub(r"\b(int|float|bool|str)\[\d+\]", r"\1", t)  # std::array: List[int[4]]
    for name in ("List", "Dict", "Optional", "Tuple", "Union", "Callable", "Iterator", "Any"):
        t = re.sub(r"(?<![\w.])%s\b" % name, "typing." + name, t)
    if "::" in t or "<" in t:
        raise SystemExit("gen_stubs: C++ type %r in a signature: register the class before "
                         "the functions that use it" % t)
    return t


def split_top(text, sep=","):
    """Splits at `sep` outside brackets, parentheses and quotes."""
    parts, depth, cur, quote = [], 0, [], None
    for ch in text:
        if quote:
            cur.append(ch)
            if ch == quote:
                quote = None
            continue
        if ch in "'\"":
            quote = ch
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == sep and depth == 0:
            parts.append("".join(cur))
            cur = []
            continue
        cur.append(ch)
    if "".join(cur).strip():
        parts.append("".join(cur))
    return parts


def parse_signature(line):
    """'name(a: int, b: str = 'x') -> float' -> (name, [(arg, type, has_default)], ret)."""
    m = re.match(r"^(\w*)\((.*)\)(?: -> (.+))?$", line.strip())
    if not m:
        raise SystemExit("gen_stubs: cannot parse signature %r" % line)
    name, args_text, ret = m.group(1), m.group(2), m.group(3) or "None"
    args = []
    for a in split_top(args_text):
        a = a.strip()
        if a.startswith("*"):
            args.append((a, None, False))
            continue
        head, eq, _ = a.partition("=")
        arg, _, typ = head.partition(":")
        args.append((arg.strip(), clean_type(typ) if typ.strip() else None, bool(eq)))
    return name, args, clean_type(ret)


def split_overloads(lines):
    """[(signature line, doc)] of the lines of an "Overloaded function." docstring, after its
    first two lines: pybind11 numbers each overload's signature ("1. name(...)")."""
    out, sig, body = [], None, []
    for line in lines:
        m = re.match(r"^\d+\. (\w+\(.*)$", line)
        if m:
            if sig:
                out.append((sig, "\n".join(body).strip()))
            sig, body = m.group(1), []
        else:
            body.append(line)
    if sig:
        out.append((sig, "\n".join(body).strip()))
    return out


def signatures(func):
    """[(signature line, doc)] of a pybind11 function, one per overload."""
    doc = func.__doc__ or ""
    lines = doc.splitlines()
    if len(lines) > 1 and lines[1].strip() == "Overloaded function.":
        return split_overloads(lines[2:])
    return [(lines[0], "\n".join(lines[1:]).strip())] if lines else []


def fmt_doc(doc, indent):
    if not doc:
        return []
    doc = doc.replace("\\", "\\\\").replace('"""', '\\"\\"\\"')
    lines = doc.splitlines()
    if len(lines) == 1:
        return [indent + '"""%s"""' % lines[0]]
    return [indent + '"""' + lines[0]] + [indent + l if l else "" for l in lines[1:]] + \
        [indent + '"""']


def fmt_def(name, sig_line, doc, indent, is_method, decorators=()):
    _, args, ret = parse_signature(sig_line)
    parts = []
    for i, (arg, typ, has_default) in enumerate(args):
        if arg.startswith("*"):
            parts.append(arg)
            continue
        if is_method and i == 0:
            parts.append(arg)  # self: the class itself
            continue
        s = arg + (": " + typ if typ else "")
        parts.append(s + (" = ..." if has_default else ""))
    out = [indent + d for d in decorators]
    out.append("%sdef %s(%s) -> %s:" % (indent, name, ", ".join(parts), ret))
    body = fmt_doc(doc, indent + "    ")
    if body:
        out += body + [indent + "    ..."]
    else:
        out[-1] += " ..."
    return out


def fmt_function(name, func, indent, is_method, static=False):
    sigs = signatures(func)
    out = []
    deco = ["@staticmethod"] if static else []
    if len(sigs) > 1:
        deco = deco + ["@typing.overload"]
    for sig, doc in sigs:
        out += fmt_def(name, sig, doc, indent, is_method and not static, deco)
    return out


def is_enum(cls):
    return hasattr(cls, "__members__") and hasattr(cls, "__entries")


def is_exception(cls):
    return issubclass(cls, BaseException)


def class_bases(cls):
    bases = [b for b in cls.__bases__ if b.__module__ == MODULE]
    if is_exception(cls):
        return [b.__name__ for b in cls.__bases__]
    return [b.__name__ for b in bases]


def fmt_class(cls, indent=""):
    bases = class_bases(cls)
    out = ["%sclass %s%s:" % (indent, cls.__name__, "(%s)" % ", ".join(bases) if bases else "")]
    inner = indent + "    "
    out += fmt_doc(cls.__doc__ if cls.__doc__ and not is_exception(cls) else
                   (cls.__doc__ or ""), inner)
    if is_exception(cls):
        return out + [inner + "..."]
    if is_enum(cls):
        for member in cls.__members__:
            out.append("%s%s: typing.ClassVar[%s]" % (inner, member, cls.__name__))
    for name, attr in sorted(cls.__dict__.items()):
        if inspect.isfunction(attr):
            continue
        if name in ("__doc__", "__module__", "__members__", "__entries") or \
                (name.startswith("__") and not isinstance(attr, (PYBIND_FUNC, staticmethod)) and
                 type(attr).__name__ != INSTANCE_METHOD):
            continue
        if is_enum(cls) and name in cls.__members__:
            continue
        if inspect.isclass(attr):
            out += fmt_class(attr, inner)
        elif isinstance(attr, property):
            _, _, ret = parse_signature(signatures(attr.fget)[0][0])
            out += ["%s@property" % inner, "%sdef %s(self) -> %s:" % (inner, name, ret)]
            doc = fmt_doc(attr.__doc__, inner + "    ")
            out += doc + [inner + "    ..."] if doc else []
            if not doc:
                out[-1] += " ..."
            if attr.fset is not None:
                _, args, _ = parse_signature(signatures(attr.fset)[0][0])
                out += ["%s@%s.setter" % (inner, name),
                        "%sdef %s(self, value: %s) -> None: ..." % (inner, name, args[1][1])]
        elif isinstance(attr, staticmethod):
            out += fmt_function(name, attr.__func__, inner, False, static=True)
        elif type(attr).__name__ == INSTANCE_METHOD or isinstance(attr, PYBIND_FUNC):
            out += fmt_function(name, attr, inner, True)
    return out


def generate(module):
    out = ['"""Type stubs of partsim._partsim, generated by scripts/gen_stubs.py from the',
           'extension\'s docstrings; regenerate after changing src/python/*.cc."""',
           "", "from __future__ import annotations", "", "import typing", "", "import numpy", ""]
    names = sorted(n for n in dir(module) if not n.startswith("_"))
    for name in names:
        obj = getattr(module, name)
        if inspect.isclass(obj) and obj.__module__ == MODULE:
            out += [""] + fmt_class(obj) + [""]
    for name in names:
        obj = getattr(module, name)
        if isinstance(obj, PYBIND_FUNC):
            out += [""] + fmt_function(name, obj, "", False)
    return "\n".join(out).rstrip() + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--python-dir", default=os.environ.get(
        "PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python")))
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--output", default=STUB)
    opts = parser.parse_args()
    sys.path.insert(0, opts.python_dir)
    module = importlib.import_module(MODULE)
    text = generate(module)
    if opts.check:
        with open(opts.output) as f:
            if f.read() != text:
                print("%s is out of date; run scripts/gen_stubs.py" % opts.output)
                return 1
        return 0
    with open(opts.output, "w") as f:
        f.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
