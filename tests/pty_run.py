"""Run a command in a pseudo-terminal of a given width and return what a person sees."""

from __future__ import annotations

import fcntl
import os
import pty
import re
import select
import struct
import subprocess
import sys
import termios


def run(args: list[str], cols: int) -> str:
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 200, cols, 0, 0))
    env = dict(os.environ, COLUMNS=str(cols), LINES="200", TERM="xterm-256color")
    p = subprocess.Popen(args, stdout=slave, stderr=slave, stdin=slave, env=env, close_fds=True)
    os.close(slave)
    chunks = []
    while True:
        ready, _, _ = select.select([master], [], [], 60)
        if not ready:
            break
        try:
            data = os.read(master, 65536)
        except OSError:
            break
        if not data:
            break
        chunks.append(data)
    p.wait()
    os.close(master)
    return re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", b"".join(chunks).decode()).replace("\r", "")
if __name__ == "__main__":  # python tests/pty_run.py 80 linkage solve
    print(run(sys.argv[2:], int(sys.argv[1])))
