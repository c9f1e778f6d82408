#!/usr/bin/env python3
"""Makes docs/models.png: one model per format, as the app shows it in a terminal.

Each model is opened with `raytty FILE` in a detached tmux window of COLS x ROWS cells; once
the frame stops changing, `tmux capture-pane -e -p` gives its cells with their colours, which
are drawn here cell by cell (half blocks as two coloured halves, other characters in DejaVu
Sans Mono). The four captures go into one 2 x 2 image, each under its caption.

    python3 docs/make_models_png.py target/release/raytty   # from the repository's root
"""

import re
import subprocess
import sys
import time

from PIL import Image, ImageDraw, ImageFont

COLS, ROWS = 64, 22
CELL_W, CELL_H = 8, 16
FONT = "/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf"
MODELS = [
    ("glTF (.glb): checker.glb, a textured cube", "tests/models/checker.glb"),
    ("OBJ + MTL: lamp.obj, an area light from its MTL", "tests/models/lamp.obj"),
    ("PLY with vertex colours: cube.ply", "tests/models/cube.ply"),
    ("STL (binary): cube_binary.stl", "tests/models/cube_binary.stl"),
]
SESSION = "raytty-models-png"
DEFAULT_FG, DEFAULT_BG = (220, 220, 220), (0, 0, 0)
# The 16 basic colours (xterm's defaults), for SGR 30-37, 40-47, 90-97, 100-107 and 38;5;n < 16.
BASIC = [
    (0, 0, 0), (205, 0, 0), (0, 205, 0), (205, 205, 0), (0, 0, 238), (205, 0, 205),
    (0, 205, 205), (229, 229, 229), (127, 127, 127), (255, 0, 0), (0, 255, 0), (255, 255, 0),
    (92, 92, 255), (255, 0, 255), (0, 255, 255), (255, 255, 255),
]


def colour_256(n):
    if n < 16:
        return BASIC[n]
    if n < 232:
        n -= 16
        level = [0, 95, 135, 175, 215, 255]
        return (level[n // 36], level[n // 6 % 6], level[n % 6])
    v = 8 + 10 * (n - 232)
    return (v, v, v)


def tmux(*args):
    return subprocess.run(["tmux", *args], capture_output=True, text=True).stdout


def capture(binary, model):
    """The settled frame of `raytty MODEL` in a COLS x ROWS window, as ANSI text."""
    tmux("kill-session", "-t", SESSION)
    tmux("new", "-d", "-s", SESSION, "-x", str(COLS), "-y", str(ROWS), f"{binary} {model}")
    last, same_since, start = None, time.time(), time.time()
    while time.time() - start < 120:
        time.sleep(0.5)
        now = tmux("capture-pane", "-e", "-p", "-t", SESSION)
        if now != last:
            last, same_since = now, time.time()
        elif time.time() - same_since > 3:
            break
    tmux("kill-session", "-t", SESSION)
    return last


def cells(text):
    """Rows of (character, fg, bg) from captured ANSI text."""
    rows = []
    fg, bg, reverse = DEFAULT_FG, DEFAULT_BG, False
    for line in text.split("\n")[:ROWS]:
        row = []
        for token in re.findall(r"\x1b\[[0-9;]*m|.", line):
            if not token.startswith("\x1b["):
                row.append((token, bg if reverse else fg, fg if reverse else bg))
                continue
            codes = [int(c) if c else 0 for c in token[2:-1].split(";")]
            i = 0
            while i < len(codes):
                c = codes[i]
                if c == 0:
                    fg, bg, reverse = DEFAULT_FG, DEFAULT_BG, False
                elif c == 7:
                    reverse = True
                elif c == 27:
                    reverse = False
                elif c in (38, 48) and i + 1 < len(codes):
                    if codes[i + 1] == 2:
                        value = tuple(codes[i + 2 : i + 5])
                        i += 4
                    else:
                        value = colour_256(codes[i + 2])
                        i += 2
                    if c == 38:
                        fg = value
                    else:
                        bg = value
                elif c == 39:
                    fg = DEFAULT_FG
                elif c == 49:
                    bg = DEFAULT_BG
                elif 30 <= c <= 37 or 90 <= c <= 97:
                    fg = BASIC[c - 30 if c < 90 else c - 90 + 8]
                elif 40 <= c <= 47 or 100 <= c <= 107:
                    bg = BASIC[c - 40 if c < 100 else c - 100 + 8]
                i += 1
        rows.append(row)
    return rows


def draw(rows, font):
    image = Image.new("RGB", (COLS * CELL_W, ROWS * CELL_H), DEFAULT_BG)
    d = ImageDraw.Draw(image)
    for y, row in enumerate(rows):
        for x, (ch, fg, bg) in enumerate(row[:COLS]):
            x0, y0 = x * CELL_W, y * CELL_H
            d.rectangle([x0, y0, x0 + CELL_W - 1, y0 + CELL_H - 1], fill=bg)
            half = CELL_H // 2
            if ch == "\u2580":
                d.rectangle([x0, y0, x0 + CELL_W - 1, y0 + half - 1], fill=fg)
            elif ch == "\u2584":
                d.rectangle([x0, y0 + half, x0 + CELL_W - 1, y0 + CELL_H - 1], fill=fg)
            elif ch == "\u2588":
                d.rectangle([x0, y0, x0 + CELL_W - 1, y0 + CELL_H - 1], fill=fg)
            elif ch != " ":
                d.text((x0, y0), ch, fill=fg, font=font)
    return image


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else "target/release/raytty"
    font = ImageFont.truetype(FONT, 13)
    caption_font = ImageFont.truetype(FONT, 15)
    pad, caption_h = 8, 24
    w, h = COLS * CELL_W, ROWS * CELL_H
    sheet = Image.new("RGB", (2 * w + 3 * pad, 2 * (h + caption_h) + 3 * pad), (40, 40, 40))
    d = ImageDraw.Draw(sheet)
    for i, (caption, model) in enumerate(MODELS):
        x = pad + (i % 2) * (w + pad)
        y = pad + (i // 2) * (h + caption_h + pad)
        d.text((x, y + 3), caption, fill=(235, 235, 235), font=caption_font)
        sheet.paste(draw(cells(capture(binary, model)), font), (x, y + caption_h))
    sheet.save("docs/models.png", optimize=True)


if __name__ == "__main__":
    main()
