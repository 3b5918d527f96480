#!/usr/bin/env python3
"""Fails when a source folder includes a folder above it in the architecture.

The layers, bottom-up: core <- accel <- materials <- renderer <- packet (batched tracing)
<- io <- denoise <- checkpoint <- distributed <- app <- python
(<- fuzz). A folder may include its own headers and those of the layers below it, never
those above: that keeps the build a DAG and the reading order from scene file to EXR straight.
"""
import pathlib
import re
import sys

ORDER = ["core", "accel", "materials", "renderer", "packet", "io", "denoise", "checkpoint", "distributed", "app", "python", "fuzz"]
ALLOWED = {layer: set(ORDER[: i + 1]) for i, layer in enumerate(ORDER)}

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
include = re.compile(r'^\s*#\s*include\s+"([a-z_]+)/[^"]+"', re.M)
errors = []
for layer in ORDER:
    folder = root / layer
    if not folder.is_dir():
        continue
    for path in sorted(folder.rglob("*")):
        if path.suffix not in (".h", ".cpp"):
            continue
        for match in include.finditer(path.read_text(encoding="utf-8")):
            target = match.group(1)
            if target in ORDER and target not in ALLOWED[layer]:
                line = path.read_text(encoding="utf-8")[: match.start()].count("\n") + 1
                errors.append(f"{path.relative_to(root)}:{line}: {layer}/ includes {target}/, a layer above it")
for e in errors:
    print(e)
print(f"layering: {len(errors)} violation(s)")
sys.exit(1 if errors else 0)
