#!/usr/bin/env python3
"""Vendors three.js for `crease view` (crates/crease/assets/three/): downloads the pinned npm
package, checks its integrity, and turns build/three.module.min.js and OrbitControls.js into
one classic script that defines `THREE` and `OrbitControls` (no import or export left), so that
the viewer page inlines it and runs with no network access and no module loading.

r170 is the last release whose module build is a single file (from r171 it imports
three.core.min.js). Run from the repository root: python3 scripts/vendor-three.py
"""

import base64
import hashlib
import io
import re
import subprocess
import tarfile
import tempfile
from pathlib import Path

VERSION = "0.170.0"
INTEGRITY = "sha512-FQK+LEpYc0fBD+J8g6oSEyyNzjp+Q7Ks1C568WWaoMRLW+TkNNWmenWeGgJjV105Gd+p/2ql1ZcjYvNiPZBhuQ=="
OUT = Path(__file__).resolve().parents[1] / "crates" / "crease" / "assets" / "three"


def bundle(three_min: str, orbit: str) -> str:
    m = re.search(r"export\{([^}]*)\};?\s*$", three_min)
    assert m, "three.module.min.js: trailing export{...} not found"
    pairs = []
    for item in m.group(1).split(","):
        mm = re.fullmatch(r"([\w$]+)(?:\s+as\s+([\w$]+))?", item.strip())
        assert mm, item
        pairs.append(f"{mm.group(2) or mm.group(1)}:{mm.group(1)}")
    body = three_min[: m.start()]
    assert not re.search(r"(^|[;}])\s*(import|export)\b", body), "import/export left in three"
    im = re.search(r"import\s*\{([^}]*)\}\s*from\s*'three';", orbit)
    assert im, "OrbitControls: import from 'three' not found"
    names = [x.strip() for x in im.group(1).split(",") if x.strip()]
    obody = orbit[: im.start()] + orbit[im.end():]
    obody, k = re.subn(r"export\s*\{\s*OrbitControls\s*\};?", "", obody)
    assert k == 1 and not re.search(r"^\s*(import|export)\b", obody, re.M)
    js = (
        f"/* three.js r{VERSION.split('.')[1]} (MIT, see LICENSE) and its OrbitControls, as one classic script */\n"
        "const THREE=(()=>{" + body + "\nreturn Object.freeze({" + ",".join(pairs) + "});})();\n"
        "const OrbitControls=(()=>{const {" + ",".join(names) + "}=THREE;\n" + obody + "\nreturn OrbitControls;})();\n"
    )
    low = js.lower()
    assert "</script" not in low and "<!--" not in low, "the bundle cannot be inlined in <script>"
    return js


def main() -> None:
    with tempfile.TemporaryDirectory() as d:
        subprocess.run(["npm", "pack", f"three@{VERSION}", "--silent"], cwd=d, check=True, capture_output=True)
        tgz = (Path(d) / f"three-{VERSION}.tgz").read_bytes()
    algo, digest = INTEGRITY.split("-", 1)
    assert base64.b64encode(hashlib.new(algo, tgz).digest()).decode() == digest, "npm integrity mismatch"
    with tarfile.open(fileobj=io.BytesIO(tgz)) as t:
        read = lambda p: t.extractfile(f"package/{p}").read().decode("utf-8")
        three_min, orbit, licence = read("build/three.module.min.js"), read(
            "examples/jsm/controls/OrbitControls.js"), read("LICENSE")
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "three.bundle.js").write_text(bundle(three_min, orbit))
    (OUT / "LICENSE").write_text(licence)
    print(f"three {VERSION}: {OUT / 'three.bundle.js'} ({(OUT / 'three.bundle.js').stat().st_size} bytes)")


if __name__ == "__main__":
    main()
