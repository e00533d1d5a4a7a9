# Compares PNG pairs (REF GOT …): mean and max absolute difference per 8-bit value, and the share
# of values that differ by more than 16. Pure Python (zlib), no imaging library; slow (≈ 2 s per 1024² pair).
import zlib, struct, sys
def load(p):
    d=open(p,'rb').read(); i=8; idat=b''
    while i<len(d):
        n,t=struct.unpack('>I4s',d[i:i+8]); c=d[i+8:i+8+n]; i+=12+n
        if t==b'IHDR': w,h,bd,ct=struct.unpack('>IIBB',c[:10])
        elif t==b'IDAT': idat+=c
    ch={2:3,6:4,0:1,4:2}[ct]; raw=zlib.decompress(idat); s=w*ch; out=bytearray(); prev=bytearray(s); o=0
    for y in range(h):
        f=raw[o]; line=bytearray(raw[o+1:o+1+s]); o+=1+s
        if f==1:
            for x in range(ch,s): line[x]=(line[x]+line[x-ch])&255
        elif f==2:
            line=bytearray((a+b)&255 for a,b in zip(line,prev))
        elif f==3:
            for x in range(s): line[x]=(line[x]+(((line[x-ch] if x>=ch else 0)+prev[x])>>1))&255
        elif f==4:
            for x in range(s):
                a=line[x-ch] if x>=ch else 0; b=prev[x]; c=prev[x-ch] if x>=ch else 0
                pa=abs(b-c); pb=abs(a-c); pc=abs(a+b-2*c)
                line[x]=(line[x]+(a if pa<=pb and pa<=pc else b if pb<=pc else c))&255
        out+=line; prev=line
    return w,h,ch,out
for a,b in zip(sys.argv[1::2],sys.argv[2::2]):
    w,h,ch,A=load(a); w2,h2,ch2,B=load(b)
    n=len(A); diff=[abs(x-y) for x,y in zip(A,B)]
    big=sum(1 for v in diff if v>16)
    print(f"{a.split('/')[-1]:34s} mean|d|={sum(diff)/n:6.3f}  max={max(diff):3d}  >16: {100*big/n:6.3f}%")
