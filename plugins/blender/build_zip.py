#!/usr/bin/env python3
"""Packs the Blender add-on as an installable zip: footfall_blender/ with the shared package
footfall_client/ inside it, and optionally libfootfall.so and footfalld next to that package.

Usage: build_zip.py --out footfall_blender.zip [--lib libfootfall.so] [--footfalld footfalld]
"""
import argparse
import os
import sys
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ADDON = os.path.join(HERE, "footfall_blender")
CLIENT = os.path.join(os.path.dirname(HERE), "python", "footfall_client")


def add_tree(z, src, arcdir):
    for name in sorted(os.listdir(src)):
        if name.endswith(".py"):
            z.write(os.path.join(src, name), arcdir + "/" + name)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--lib")
    ap.add_argument("--footfalld")
    args = ap.parse_args()
    tmp = args.out + ".tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        add_tree(z, ADDON, "footfall_blender")
        add_tree(z, CLIENT, "footfall_blender/footfall_client")
        for path in (args.lib, args.footfalld):
            if path:
                if not os.path.isfile(path):
                    sys.exit("build_zip: %s: no such file" % path)
                info = zipfile.ZipInfo("footfall_blender/footfall_client/" + os.path.basename(path))
                info.external_attr = 0o755 << 16
                info.compress_type = zipfile.ZIP_DEFLATED
                with open(path, "rb") as f:
                    z.writestr(info, f.read())
    os.replace(tmp, args.out)


if __name__ == "__main__":
    main()
