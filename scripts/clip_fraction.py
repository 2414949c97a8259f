#!/usr/bin/env python3
"""The share of pixels at white (some channel 255) in 8-bit RGB PNG files, and their mean 8-bit
value: what the automatic exposure keeps at or below 1 % (issue #43). Pure Python (zlib only), so
it needs no image library.

Usage: scripts/clip_fraction.py IMAGE.png [...]
"""
import sys, zlib, struct
def read_png(path):
    d=open(path,'rb').read(); assert d[:8]==b'\x89PNG\r\n\x1a\n'
    i=8; idat=b''; w=h=0
    while i<len(d):
        n,=struct.unpack('>I',d[i:i+4]); t=d[i+4:i+8]; c=d[i+8:i+8+n]; i+=12+n
        if t==b'IHDR': w,h,bd,ct=struct.unpack('>IIBB',c[:10]); assert bd==8 and ct==2, (bd,ct)
        elif t==b'IDAT': idat+=c
    raw=zlib.decompress(idat); bpp=3; stride=w*3; out=bytearray(); prev=bytearray(stride); p=0
    for y in range(h):
        f=raw[p]; line=bytearray(raw[p+1:p+1+stride]); p+=1+stride
        for x in range(stride):
            a=line[x-bpp] if x>=bpp else 0; b=prev[x]; cc=prev[x-bpp] if x>=bpp else 0
            if f==1: line[x]=(line[x]+a)&255
            elif f==2: line[x]=(line[x]+b)&255
            elif f==3: line[x]=(line[x]+(a+b)//2)&255
            elif f==4:
                pp=a+b-cc; pa=abs(pp-a); pb=abs(pp-b); pc=abs(pp-cc)
                pr=a if pa<=pb and pa<=pc else (b if pb<=pc else cc)
                line[x]=(line[x]+pr)&255
        out+=line; prev=line
    return w,h,out
for path in sys.argv[1:]:
    w,h,px=read_png(path)
    n=w*h; clip=sum(1 for k in range(n) if 255 in px[3*k:3*k+3])
    mean=sum(px)/len(px)
    print(f"{path}: {w}x{h} clipped {100*clip/n:.2f}% mean8 {mean:.1f}")
