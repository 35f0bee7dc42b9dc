#!/usr/bin/env python3
"""Copies a u-blox UBX log with real-receiver faults added, for the tests of the fusion's input
checks (tests/fusion/real_walk_quirks.sh).

    mutate_ubx.py IN OUT [--clock-jump MS@S ...] [--flip-doppler] [--late-ephemeris S]
                         [--code-bias SATS:M@S0-S1 ...]

  --clock-jump MS@S   from S seconds after the first RXM-RAWX epoch on, every pseudorange moves by
                      MS·c·1 ms and every carrier phase by MS·1 ms·f cycles (a receiver clock jump
                      as a free-running u-blox clock makes it; repeatable, jumps add up)
  --flip-doppler      every RXM-RAWX Doppler negated (the opposite sign convention)
  --late-ephemeris S  RXM-SFRBX messages of the first S seconds removed (ephemerides arrive late)
  --code-bias SATS:M@S0-S1
                      every pseudorange of the satellites SATS (e.g. G10,E07) moves by M metres from
                      S0 to S1 seconds after the first RXM-RAWX epoch, carrier phases untouched (a
                      burst of NLOS or multipath code errors; repeatable)

RXM-RAWX layout (u-blox interface description, UBX-RXM-RAWX): 16-byte header (rcvTow R8, week U2,
...), then 32 bytes per measurement: prMes R8 at 0, cpMes R8 at 8, doMes R4 at 16, gnssId U1 at
20, svId U1 at 21, sigId U1 at 22, freqId U1 at 23. Frames keep their length; checksums are recomputed.
"""
import argparse
import struct
import sys

C = 299792458.0
SYNC = b"\xb5\x62"
# Carrier frequency (MHz) per gnssId and sigId (u-blox signal identifiers).
BANDS = {
    0: {0: 1575.42, 3: 1227.60, 4: 1227.60, 6: 1176.45, 7: 1176.45},
    1: {0: 1575.42},
    2: {0: 1575.42, 1: 1575.42, 3: 1176.45, 4: 1176.45, 5: 1207.14, 6: 1207.14, 8: 1278.75, 9: 1278.75, 10: 1278.75},
    3: {0: 1561.098, 1: 1561.098, 2: 1207.14, 3: 1207.14, 4: 1268.52, 10: 1268.52, 5: 1575.42, 6: 1575.42,
        7: 1176.45, 8: 1176.45},
    5: {0: 1575.42, 1: 1575.42, 4: 1227.60, 5: 1227.60, 8: 1176.45, 9: 1176.45},
    7: {0: 1176.45},
}


# RINEX system letter per gnssId.
LETTER = {0: "G", 1: "S", 2: "E", 3: "C", 5: "J", 6: "R"}


def frequency(gnss, sig, freq_id):
    if gnss == 6:  # GLONASS FDMA, channel k = freqId - 7
        k = freq_id - 7
        return {0: 1602.0 + 0.5625 * k, 2: 1246.0 + 0.4375 * k}.get(sig)
    return BANDS.get(gnss, {}).get(sig)


def checksum(body):
    a = b = 0
    for x in body:
        a = (a + x) & 0xFF
        b = (b + a) & 0xFF
    return bytes((a, b))


def frames(data):
    """(offset, class, id, payload) of each frame with a valid checksum; other bytes as (offset, None, None, bytes)."""
    i = 0
    while i < len(data):
        j = data.find(SYNC, i)
        if j < 0 or j + 8 > len(data):
            yield i, None, None, data[i:]
            return
        if j > i:
            yield i, None, None, data[i:j]
        n = struct.unpack_from("<H", data, j + 4)[0]
        end = j + 8 + n
        if end <= len(data) and checksum(data[j + 2:j + 6 + n]) == data[j + 6 + n:end]:
            yield j, data[j + 2], data[j + 3], data[j + 6:j + 6 + n]
            i = end
        else:
            yield j, None, None, data[j:j + 2]
            i = j + 2


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("inp")
    ap.add_argument("out")
    ap.add_argument("--clock-jump", action="append", default=[])
    ap.add_argument("--flip-doppler", action="store_true")
    ap.add_argument("--late-ephemeris", type=float, default=0.0)
    ap.add_argument("--code-bias", action="append", default=[])
    a = ap.parse_args()
    biases = []  # (satellites, metres, start, end)
    for b in a.code_bias:
        sats, rest = b.split(":")
        m, span = rest.split("@")
        s0, s1 = span.split("-")
        biases.append((set(sats.split(",")), float(m), float(s0), float(s1)))
    jumps = []
    for j in a.clock_jump:
        ms, at = j.split("@")
        jumps.append((float(at), int(ms)))
    data = open(a.inp, "rb").read()
    out = bytearray()
    t0 = tow = None
    counts = {"rawx": 0, "jumped": 0, "sfrbx_removed": 0, "biased": 0}
    for _, cls, mid, payload in frames(data):
        if cls is None:
            out += payload
            continue
        p = bytearray(payload)
        if (cls, mid) == (0x02, 0x15) and len(p) >= 16:
            tow = struct.unpack_from("<d", p, 0)[0]
            t0 = tow if t0 is None else t0
            counts["rawx"] += 1
            ms = sum(k for at, k in jumps if tow - t0 >= at)
            n = p[11]
            for i in range(n):
                o = 16 + 32 * i
                if o + 32 > len(p):
                    break
                pr, cp = struct.unpack_from("<dd", p, o)
                dop = struct.unpack_from("<f", p, o + 16)[0]
                f = frequency(p[o + 20], p[o + 22], p[o + 23])
                if ms:
                    if pr != 0.0:
                        pr += ms * 1e-3 * C
                    if cp != 0.0 and f:
                        cp += ms * 1e-3 * f * 1e6
                    counts["jumped"] += 1
                sat = "%s%02d" % (LETTER.get(p[o + 20], "?"), p[o + 21])
                for sats, m, s0, s1 in biases:
                    if sat in sats and s0 <= tow - t0 < s1 and pr != 0.0:
                        pr += m
                        counts["biased"] += 1
                if a.flip_doppler:
                    dop = -dop
                struct.pack_into("<ddf", p, o, pr, cp, dop)
        elif (cls, mid) == (0x02, 0x13) and a.late_ephemeris > 0 and (t0 is None or tow - t0 < a.late_ephemeris):
            counts["sfrbx_removed"] += 1
            continue
        body = bytes((cls, mid)) + struct.pack("<H", len(p)) + bytes(p)
        out += SYNC + body + checksum(body)
    open(a.out, "wb").write(out)
    print("mutate_ubx: %d RAWX epochs, %d measurements jumped, %d SFRBX removed, %d pseudoranges biased" %
          (counts["rawx"], counts["jumped"], counts["sfrbx_removed"], counts["biased"]), file=sys.stderr)


if __name__ == "__main__":
    main()
