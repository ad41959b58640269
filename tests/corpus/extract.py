#!/usr/bin/env python3
"""Copy the files of one commit of a bare git directory into a corpus folder.

Usage: extract.py GIT_DIR DEST [COMMIT]

Blobs of 4 MiB and more are skipped, as are blobs the snapshot lacks (the
snapshots `fetch` brings hold no file of 4 MiB or more, nor Git LFS content);
a scene that needs one of them is then counted under "assets missing" by
open-rate.sh, not as a refusal. Prints the commit and the counts.
"""

import os
import subprocess
import sys

LIMIT = 4 * 1024 * 1024


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    git_dir, dest = sys.argv[1], sys.argv[2]
    commit = sys.argv[3] if len(sys.argv) == 4 else "HEAD"
    git = ["git", "--git-dir", git_dir]
    full = subprocess.run(git + ["rev-parse", commit], capture_output=True, text=True, check=True).stdout.strip()
    listing = subprocess.run(git + ["ls-tree", "-r", "-l", "-z", full], capture_output=True, check=True).stdout
    wanted = []
    skipped = 0
    for entry in listing.split(b"\0"):
        if not entry:
            continue
        meta, path = entry.split(b"\t", 1)
        mode, kind, sha, size = meta.split()
        if kind != b"blob" or mode == b"120000":
            continue
        if not size.isdigit() or int(size) >= LIMIT:
            skipped += 1
            continue
        wanted.append((sha.decode(), path.decode("utf-8", "surrogateescape")))
    cat = subprocess.Popen(git + ["cat-file", "--batch"], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    written = 0
    for sha, path in wanted:
        cat.stdin.write(sha.encode() + b"\n")
        cat.stdin.flush()
        header = cat.stdout.readline().split()
        if len(header) < 3:
            skipped += 1  # "<sha> missing": the snapshot lacks this blob
            continue
        data = cat.stdout.read(int(header[2]))
        cat.stdout.read(1)
        target = os.path.join(dest, path)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        with open(target, "wb") as out:
            out.write(data)
        written += 1
    cat.stdin.close()
    cat.wait()
    print(f"{git_dir} {full}: {written} files written, {skipped} skipped")


if __name__ == "__main__":
    main()
