#!/usr/bin/python3
"""Independent DBC decoder for candump -L logs (Python standard library only; python3-cantools
is not in Debian 12). It knows nothing of the firmware's source: it parses the DBC file's BO_,
SG_ and VAL_ lines and decodes every frame of the log with them.

usage: dbc_decode.py DBC LOG [--expect JSON_FILE] [--series CSV_FILE]
Prints one JSON object: frame counts per message, the last value of every signal, pose groups
(complete, lost by sequence gaps, incomplete) and the final complete pose group.
With --expect FILE (odometryd --json output): exit 1 unless the final pose group equals the
daemon's final x, y, theta within half the DBC resolution (+1e-9), and every frame was known.
With --series FILE: every complete pose group as CSV (time,seq,x,y,theta).
"""
import json
import math
import re
import sys

BO_RE = re.compile(r'^BO_\s+(\d+)\s+(\w+)\s*:\s*(\d+)\s+(\w+)')
SG_RE = re.compile(
    r'^\s*SG_\s+(\w+)\s*:\s*(\d+)\|(\d+)@([01])([+-])\s*\(([^,]+),([^)]+)\)\s*'
    r'\[([^|]+)\|([^\]]+)\]\s*"([^"]*)"')
LOG_RE = re.compile(r'^\((\d+)\.(\d+)\)\s+(\S+)\s+([0-9A-Fa-f]+)#([0-9A-Fa-f]*)$')


def parse_dbc(path):
    msgs = {}
    cur = None
    with open(path, encoding='ascii') as f:
        for line in f:
            m = BO_RE.match(line)
            if m:
                cur = {'name': m.group(2), 'dlc': int(m.group(3)), 'signals': []}
                msgs[int(m.group(1))] = cur
                continue
            m = SG_RE.match(line)
            if m and cur is not None:
                if m.group(4) != '1':
                    raise SystemExit('only Intel byte order is used by this protocol')
                cur['signals'].append({
                    'name': m.group(1), 'start': int(m.group(2)), 'len': int(m.group(3)),
                    'signed': m.group(5) == '-', 'scale': float(m.group(6)),
                    'offset': float(m.group(7)), 'min': float(m.group(8)),
                    'max': float(m.group(9)), 'unit': m.group(10)})
            elif not line.strip():
                cur = None
    return msgs


def decode(sig, data):
    word = int.from_bytes(data.ljust(8, b'\0'), 'little')
    raw = (word >> sig['start']) & ((1 << sig['len']) - 1)
    if sig['signed'] and raw & (1 << (sig['len'] - 1)):
        raw -= 1 << sig['len']
    return raw * sig['scale'] + sig['offset']


def main(argv):
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    msgs = parse_dbc(argv[1])
    expect = None
    if '--expect' in argv:
        with open(argv[argv.index('--expect') + 1]) as f:
            expect = json.load(f)
    counts, last, unknown = {}, {}, 0
    groups = {}  # seq -> {'x':..., 'y':..., 'theta':...} of the group being built
    complete, incomplete, lost = 0, 0, 0
    final = None
    prev_seq = None
    out_of_range = []
    series = []
    with open(argv[2], encoding='ascii') as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            m = LOG_RE.match(line)
            if not m:
                raise SystemExit(f'{argv[2]}:{n}: not a candump -L line')
            can_id = int(m.group(4), 16)
            data = bytes.fromhex(m.group(5))
            msg = msgs.get(can_id)
            if msg is None:
                unknown += 1
                continue
            counts[msg['name']] = counts.get(msg['name'], 0) + 1
            vals = {s['name']: decode(s, data) for s in msg['signals']}
            for s in msg['signals']:
                v = vals[s['name']]
                if v < s['min'] - 1e-9 or v > s['max'] + 1e-9:
                    out_of_range.append(f"{n}: {s['name']}={v}")
            last.update(vals)
            stamp = float(m.group(1) + '.' + m.group(2))
            if msg['name'] in ('PoseX', 'PoseYTheta'):
                seq = int(vals['seq'])
                g = groups.setdefault(seq, {})
                g.update({k: v for k, v in vals.items() if k != 'seq'})
                if msg['name'] == 'PoseX':
                    # A new group starts: the previous one must have been complete, and the
                    # sequence must step by one.
                    if prev_seq is not None and seq != (prev_seq + 1) % 256:
                        lost += (seq - prev_seq - 1) % 256
                    prev_seq = seq
                if {'x', 'y', 'theta'} <= g.keys():
                    complete += 1
                    final = dict(g, seq=seq)
                    series.append((stamp, seq, g['x'], g['y'], g['theta']))
                    del groups[seq]
    incomplete = len(groups)
    res = {'frames': sum(counts.values()) + unknown, 'unknown_frames': unknown,
           'messages': counts, 'last': last, 'pose_groups': {
               'complete': complete, 'incomplete': incomplete, 'lost': lost},
           'final_pose': final, 'out_of_range': out_of_range[:10]}
    rc = 0
    if expect is not None:
        res_pose = {}
        sigs = {s['name']: s for m in msgs.values() for s in m['signals']}
        for k in ('x', 'y', 'theta'):
            tol = sigs[k]['scale'] / 2 + 1e-9
            want = expect[k]
            got = final[k] if final else float('nan')
            d = abs(got - want)
            if k == 'theta':
                d = min(d, abs(d - 2 * math.pi))
            res_pose[k] = {'dbc': got, 'daemon': want, 'diff': d, 'tolerance': tol,
                           'ok': d <= tol}
            rc |= 0 if d <= tol else 1
        res['compare'] = res_pose
        if unknown or out_of_range or not final:
            rc = 1
    if '--series' in argv:
        with open(argv[argv.index('--series') + 1], 'w') as f:
            f.write('time,seq,x,y,theta\n')
            for row in series:
                f.write('%.6f,%d,%.4f,%.4f,%.4f\n' % row)
    print(json.dumps(res, sort_keys=True))
    return rc


if __name__ == '__main__':
    sys.exit(main(sys.argv))
