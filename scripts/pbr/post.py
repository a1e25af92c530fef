#!/usr/bin/python3
"""Step 2 of scripts/pbr/render.sh: turns one scene's Blender output into a test case.

usage: post.py --raw WORK/SCENE --out tests/pbr/SCENE --softsight PROGRAM

Reads RAW/truth.json and RAW/frames/NNNN.png (frame 0 whole, the others only inside the
`render_crop` box where something moves: they are pasted onto frame 0), removes most render noise
(a stand-in for the denoiser Debian's Blender lacks), adds sensor noise, encodes
the video as a camera would (MJPG in .avi or H.264 in .mp4), and writes into OUT:
  video.avi | video.mp4   the footage
  truth.csv               frame, marker, x, y, visible, visibility (exact; see scene.json)
  angles.csv              frame, the true angle (deg) at each inner marker from the projected centres
  scene.json              the scene's settings and conventions
  pick.yaml               `softsight pick --at` the frame-0 centres, as clicks in `live` give them
  zncc.yaml               a box per marker (its frame-0 outline + 6 px), as dragged in `live`
  achromatic.yaml         (white or black dots only) a gray range with a roi per dot, as examples/markers.yaml
Needs numpy and OpenCV; no Blender.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

import cv2
import numpy as np

MARGIN = 6          # px around a marker's outline for its template box (as the outsider's zncc.yaml)


def names_for(colours):
    """Truth names: the colour, numbered when colours repeat (white dots: white0, white1, ...)."""
    if len(set(colours)) == len(colours):
        return list(colours)
    return [f'{c}{k}' for k, c in enumerate(colours)]


def compose(raw, meta):
    """Frame f = frame 0 with the crop box replaced by render f. Cycles renders a border at whole
    pixels; 2 px inside it are taken so a rounding of the border never pastes black."""
    plate = cv2.imread(os.path.join(raw, 'frames', '0000.png'), cv2.IMREAD_COLOR)
    x0, y0, x1, y1 = meta['render_crop']
    x0, y0 = x0 + 2 if x0 > 0 else 0, y0 + 2 if y0 > 0 else 0
    x1 = x1 - 2 if x1 < meta['width'] else x1
    y1 = y1 - 2 if y1 < meta['height'] else y1
    for f in range(meta['frames']):
        if f == 0:
            yield plate.copy()
            continue
        img = cv2.imread(os.path.join(raw, 'frames', f'{f:04d}.png'), cv2.IMREAD_COLOR)
        out = plate.copy()
        out[y0:y1, x0:x1] = img[y0:y1, x0:x1]
        yield out


def denoise(img):
    """Debian's Blender has no OpenImageDenoise: a mild non-local-means filter stands in for it,
    removing most of the path tracer's speckle at 12 samples (which a camera does not show, and
    which would double the MJPG's size) before the camera's own noise is added."""
    return cv2.fastNlMeansDenoisingColored(img, None, 5, 5, 5, 15)


def add_noise(img, sigma, rng):
    """Sensor noise in digital numbers: a read-noise floor `sigma` plus shot noise growing with the
    signal (variance 0.02 DN per DN), independent per channel, then rounded and clipped."""
    f = img.astype(np.float32)
    sd = np.sqrt(sigma * sigma + 0.02 * f)
    return np.clip(np.rint(f + rng.standard_normal(f.shape).astype(np.float32) * sd), 0, 255).astype(np.uint8)


def writer(path, codec, size, fps):
    if codec == 'mjpg':
        # FFmpeg's MJPEG at OpenCV's default quality: ~45 KB a frame here, as a webcam's MJPG.
        # (OpenCV's own MJPEG writer takes a quality but writes 2-3 times larger frames.)
        w = cv2.VideoWriter(path, cv2.CAP_FFMPEG, cv2.VideoWriter_fourcc(*'MJPG'), fps, size)
    else:
        w = cv2.VideoWriter(path, cv2.CAP_FFMPEG, cv2.VideoWriter_fourcc(*'avc1'), fps, size)
    if not w.isOpened():
        sys.exit(f'post.py: cannot open a {codec} writer for {path}')
    return w


def angle_at(a, b, c):
    """The angle (deg, 0-180) at b between a and c, in image coordinates."""
    d = math.degrees(math.atan2(a[1] - b[1], a[0] - b[0]) - math.atan2(c[1] - b[1], c[0] - b[0])) % 360
    return min(d, 360 - d)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument('--raw', required=True)
    p.add_argument('--out', required=True)
    p.add_argument('--softsight', required=True)
    a = p.parse_args()
    with open(os.path.join(a.raw, 'truth.json')) as f:
        meta = json.load(f)
    os.makedirs(a.out, exist_ok=True)
    colours = [m['colour'] for m in meta['markers']]
    names = names_for(colours)
    n = len(names)

    # video
    video = 'video.avi' if meta['codec'] == 'mjpg' else 'video.mp4'
    for old in ('video.avi', 'video.mp4'):
        if os.path.exists(os.path.join(a.out, old)):
            os.remove(os.path.join(a.out, old))
    rng = np.random.default_rng(meta['seed'])
    w = writer(os.path.join(a.out, video), meta['codec'], (meta['width'], meta['height']), meta['fps'])
    for img in compose(a.raw, meta):
        w.write(add_noise(denoise(img), meta['sensor_noise_sigma_dn'], rng))
    w.release()

    # truth
    by_frame = {}
    with open(os.path.join(a.out, 'truth.csv'), 'w', newline='') as f:
        out = csv.writer(f, lineterminator='\n')
        out.writerow(['frame', 'marker', 'x', 'y', 'visible', 'visibility'])
        for r in meta['rows']:
            vis = r['visibility']
            out.writerow([r['frame'], names[r['marker']], f"{r['x']:.4f}", f"{r['y']:.4f}",
                          int(vis >= 0.5), f'{vis:.3f}'])
            by_frame.setdefault(r['frame'], {})[r['marker']] = (r['x'], r['y'])
    inner = names[1:-1]
    with open(os.path.join(a.out, 'angles.csv'), 'w', newline='') as f:
        out = csv.writer(f, lineterminator='\n')
        out.writerow(['frame'] + [f'angle_{m}_deg' for m in inner])
        for fr in sorted(by_frame):
            p_ = by_frame[fr]
            out.writerow([fr] + [f'{angle_at(p_[k - 1], p_[k], p_[k + 1]):.4f}' for k in range(1, n - 1)])

    # scene.json: the settings, without the per-frame rows (those are truth.csv)
    scene = {k: v for k, v in meta.items() if k != 'rows'}
    scene['video'] = video
    scene['triple'] = names if n == 3 else None
    scene['chain'] = names if n > 3 else None
    for m, name in zip(scene['markers'], names):
        m['name'] = name
        x0, y0, x1, y1 = m.pop('bbox_frame0')
        m['bbox'] = [math.floor(x0), math.floor(y0), math.ceil(x1) - math.floor(x0), math.ceil(y1) - math.floor(y0)]
    scene['files'] = dict(truth='truth.csv: frame, marker, x, y, visible (visibility >= 0.5), visibility',
                          angles='angles.csv: the true angle at each inner marker, from the projected centres')
    with open(os.path.join(a.out, 'scene.json'), 'w') as f:
        json.dump(scene, f, indent=1)

    # configs a user would make on frame 0
    first = by_frame[0]
    body = f'triple: [{", ".join(names)}]' if n == 3 else f'chain: [{", ".join(names)}]'
    ats = [arg for k in range(n) for arg in ('--at', f'{first[k][0]:.0f},{first[k][1]:.0f}')]
    done = subprocess.run([os.path.abspath(a.softsight), 'pick', '-i', video, '--frame', '0', *ats,
                           '-o', 'pick.yaml'], cwd=a.out, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f'post.py: softsight pick failed: {done.stderr.strip()}')
    with open(os.path.join(a.out, 'pick.yaml')) as f:
        picked = f.read()
    with open(os.path.join(a.out, 'pick.yaml'), 'w') as f:
        f.write('# written by `softsight pick --at` at the markers\' centres in frame 0 (truth.csv), '
                'rounded to whole pixels\n' + picked)
    boxes = [[b[0] - MARGIN, b[1] - MARGIN, b[2] + 2 * MARGIN, b[3] + 2 * MARGIN]
             for b in (m['bbox'] for m in scene['markers'])]
    with open(os.path.join(a.out, 'zncc.yaml'), 'w') as f:
        f.write('# Template config a user would drag in `softsight live` on frame 0: a box around each '
                f'marker\n# (its frame-0 outline from scene.json plus {MARGIN} px), method zncc, every '
                'other key default.\nmarkers:\n')
        for name, b in zip(names, boxes):
            f.write(f'  - name: {name}\n    method: zncc\n    template: {{frame: 0, rect: {b}}}\n')
        f.write(body + '\n')
    # White or black dots: a range by gray level alone, as examples/markers.yaml gives them.
    achromatic = {
        'white': ('White dots by brightness alone (the gray range of examples/markers.yaml, as '
                  'tests/real/mire2)', 'hsv: {h: [0, 179], s: [0, 60], v: [170, 255]}'),
        'black': ('Black dots by darkness alone (the gray range examples/markers.yaml gives for '
                  'black dots)', 'gray: [0, 50]'),
    }.get(colours[0]) if len(set(colours)) == 1 else None
    if achromatic:
        what, rule = achromatic
        with open(os.path.join(a.out, 'achromatic.yaml'), 'w') as f:
            f.write(f'# {what},\n# a roi per dot: its frame-0 outline plus {MARGIN} px.\nmarkers:\n')
            for name, b in zip(names, boxes):
                f.write(f'  - name: {name}\n    {rule}\n    roi: {b}\n')
            f.write(body + '\n')
    print(f'post.py: {a.out}: {video} {os.path.getsize(os.path.join(a.out, video)) / 1e6:.2f} MB, '
          f'{meta["frames"]} frames, markers {", ".join(names)}')


if __name__ == '__main__':
    main()
