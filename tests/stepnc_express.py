#!/usr/bin/env python3
"""Validates STEP-NC Part 21 files against an ISO 14649 EXPRESS schema with ifcopenshell.

Usage: stepnc_express.py SCHEMA.exp FILE.stp...

Prints one line per file (`ok FILE` or `FAIL FILE: n issues`, then the issues) and exits 1
when any file has an issue, 2 when ifcopenshell is missing.

ifcopenshell is built for IFC; it validates other schemas with these adjustments (see
../shared/reference/stepnc/NOTES.md): the schema text loses its (nested) comments and its
duplicate declarations, every identifier outside string literals is upper-cased, stub
entities ifcopenshell expects are appended, the declaration names are sorted the way its
C++ lookup searches them, and the files name the schema in FILE_SCHEMA.
"""

import os
import re
import sys
import tempfile

try:
    import ifcopenshell
    import ifcopenshell.express
    import ifcopenshell.validate as validate
except ImportError:
    print("ifcopenshell is not installed")
    sys.exit(2)


def strip_comments(text):
    """Removes `(* ... *)` comments, nested ones included, and `--` line comments, outside
    string literals."""
    out = []
    i, depth, n = 0, 0, len(text)
    in_str = False
    while i < n:
        c = text[i]
        if depth == 0 and c == "'":
            in_str = not in_str
            out.append(c)
            i += 1
        elif in_str:
            out.append(c)
            i += 1
        elif text.startswith("(*", i):
            depth += 1
            i += 2
        elif depth and text.startswith("*)", i):
            depth -= 1
            i += 2
        elif depth:
            i += 1
        elif text.startswith("--", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def upper_outside_strings(text):
    parts = re.split(r"('(?:[^']|'')*')", text)
    return "".join(p if k % 2 else p.upper() for k, p in enumerate(parts))


def drop_duplicates(text):
    """Keeps the first of each TYPE/ENTITY/FUNCTION/RULE declaration of one name."""
    seen = set()
    out = []
    pattern = re.compile(r"\b(TYPE|ENTITY|FUNCTION|RULE|PROCEDURE)\s+(\w+)(.*?)\bEND_\1\s*;", re.S)
    pos = 0
    for m in pattern.finditer(text):
        out.append(text[pos : m.start()])
        key = (m.group(1), m.group(2))
        if key not in seen:
            seen.add(key)
            out.append(m.group(0))
        pos = m.end()
    out.append(text[pos:])
    return "".join(out)


STUBS = """
ENTITY IFCROOT; END_ENTITY;
ENTITY IFCRELATIONSHIP; END_ENTITY;
ENTITY IFCAPPLICATION; END_ENTITY;
"""


def load_schema(path):
    text = open(path, encoding="utf-8", errors="replace").read()
    text = upper_outside_strings(drop_duplicates(strip_comments(text)))
    name = re.search(r"\bSCHEMA\s+(\w+)\s*;", text).group(1)
    text = re.sub(r"\bEND_SCHEMA\s*;", STUBS + "END_SCHEMA;", text, count=1)
    tmp = tempfile.NamedTemporaryFile("w", suffix=".exp", delete=False)
    tmp.write(text)
    tmp.close()
    import schema_class  # on the path ifcopenshell.express adds

    # The C++ lookup searches declarations in upper-case order.
    schema_class.LateBoundSchemaInstantiator.begin_schema = lambda self: self.names.sort(key=str.upper)
    schema = ifcopenshell.express.parse(tmp.name)
    ifcopenshell.register_schema(schema)
    os.unlink(tmp.name)
    return name


def check(path, schema_name):
    text = open(path, encoding="utf-8").read()
    text = re.sub(r"FILE_SCHEMA\s*\(\s*\((.*?)\)\s*\)", f"FILE_SCHEMA(('{schema_name}'))", text, count=1, flags=re.S)
    tmp = tempfile.NamedTemporaryFile("w", suffix=".stp", delete=False)
    tmp.write(text)
    tmp.close()
    issues = []
    ifcopenshell.get_log()  # clear
    try:
        f = ifcopenshell.open(tmp.name)
    except Exception as e:  # the file does not parse at all
        os.unlink(tmp.name)
        return [f"unreadable: {e}"]
    os.unlink(tmp.name)
    for line in filter(None, ifcopenshell.get_log().split("\n")):
        issues.append(line.strip())
    schema = ifcopenshell.schema_by_name(schema_name)
    for inst in f:
        try:
            entity, attrs = validate.get_entity_attributes(schema, inst.is_a())
        except Exception as e:
            issues.append(f"#{inst.id()} {inst.is_a()}: unknown entity ({e})")
            continue
        if len(inst) != len(attrs):
            issues.append(f"#{inst.id()} {inst.is_a()}: {len(inst)} attributes, the schema has {len(attrs)}")
            continue
        for i, attr in enumerate(attrs):
            val = inst[i]
            if val is None:
                if not attr.optional():
                    issues.append(f"#{inst.id()} {inst.is_a()}.{attr.name()}: $ where the attribute is not optional")
                continue
            try:
                validate.assert_valid(attr.type_of_attribute(), val, schema, attr=attr)
            except Exception as e:
                issues.append(f"#{inst.id()} {inst.is_a()}.{attr.name()}: {str(e).strip()}")
    return issues


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        sys.exit(2)
    name = load_schema(sys.argv[1])
    bad = 0
    for path in sys.argv[2:]:
        issues = check(path, name)
        if issues:
            bad += 1
            print(f"FAIL {path}: {len(issues)} issues")
            for m in issues[:20]:
                print(f"  {m}")
        else:
            print(f"ok {path}")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
