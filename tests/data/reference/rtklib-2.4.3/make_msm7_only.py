#!/usr/bin/env python3
# Makes the input of rtcm_uscl_msm7_convbin.obs.gz (SRI-GVINS test data; our own script):
#   python3 make_msm7_only.py ../../rtcm/pyrtcm_pygpsdata-NTRIP-USCL00CHL0.log uscl_msm7.rtcm3
#   convbin -r rtcm3 -tr 2024/03/13 12:00:00 -v 3.03 -od -os -d OUTDIR uscl_msm7.rtcm3
#   gzip -9 -n OUTDIR/uscl_msm7.obs, renamed rtcm_uscl_msm7_convbin.obs.gz
# The pyrtcm log holds, for the same epoch, legacy observations (1003/1004, 1009-1012) and MSM6
# and MSM7 of every system, and their values disagree (the legacy GPS/GLONASS ranges differ from
# the MSM7 ones by 0.36 ms). RTKLIB keeps the last message's value and we the first, so the
# comparison uses the MSM7 frames alone: this script copies every frame except the legacy
# observation messages 1001-1004, 1009-1012 and MSM1-MSM6 (1071-1076 ... 1131-1136), unchanged.
import sys
d = open(sys.argv[1], 'rb').read()
out = bytearray()
i = 0
while i < len(d):
    if d[i] == 0xD3 and i + 3 <= len(d):
        n = ((d[i + 1] & 3) << 8) | d[i + 2]
        if i + n + 6 <= len(d):
            t = (d[i + 3] << 4) | (d[i + 4] >> 4)
            legacy = 1001 <= t <= 1004 or 1009 <= t <= 1012
            low_msm = 1071 <= t <= 1137 and 1 <= t % 10 <= 6
            if not (legacy or low_msm):
                out += d[i:i + n + 6]
            i += n + 6
            continue
    i += 1
open(sys.argv[2], 'wb').write(out)
