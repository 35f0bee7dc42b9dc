#!/usr/bin/env python3
# Makes the input of rtcm_gmsd_nobds_convbin.obs.gz (SRI-GVINS test data; our own script):
#   python3 make_gmsd_nobds.py ../../rtcm/rtklib_GMSD7_20121014.rtcm3 gmsd_nobds.rtcm3
#   convbin -r rtcm3 -tr 2012/10/13 23:00:00 -v 3.03 -od -os -d OUTDIR gmsd_nobds.rtcm3
#   gzip -9 -n OUTDIR/gmsd_nobds.obs, renamed rtcm_gmsd_nobds_convbin.obs.gz
# RTKLIB 2.4.3 b34 ends an MSM epoch only at a message whose multiple-message bit is clear; in the
# GMSD log that is the BeiDou 1127, whose GPS-time stamp RTKLIB misreads, so it converts BeiDou
# only. This script drops the BeiDou MSM7 (1127) frames of rtklib_GMSD7_20121014.rtcm3 and clears the
# multiple-message bit (DF393, payload bit 54) of the QZSS MSM7 (1117) frame that preceded each
# of them, re-sealing it with a fresh CRC-24Q; every other byte is copied unchanged.
import sys
def crc24q(b):
    crc=0
    for x in b:
        crc^=x<<16
        for _ in range(8):
            crc<<=1
            if crc&0x1000000: crc^=0x1864CFB
    return crc&0xFFFFFF
d=open(sys.argv[1],'rb').read(); out=bytearray(); i=0
while i<len(d):
    if d[i]==0xD3 and i+3<=len(d):
        L=((d[i+1]&3)<<8)|d[i+2]
        if i+L+6<=len(d):
            f=bytearray(d[i:i+L+6]); t=(f[3]<<4)|(f[4]>>4)
            if t!=1127:
                if t==1117:
                    f[3+54//8]&=~(0x80>>(54%8))&0xFF
                    c=crc24q(f[:L+3]); f[L+3:L+6]=c.to_bytes(3,'big')
                out+=f
            i+=L+6; continue
    i+=1
open(sys.argv[2],'wb').write(out)
