"""Make examples/brain_tetgen.node/.ele: python3 scripts/make_example.py tests/data/brain_20k.stl examples/brain_tetgen pq1.4YQ (needs pip install tetgen numpy)."""
import numpy as np, tetgen, struct, sys
def read_stl(p):
    b=open(p,'rb').read(); n=struct.unpack('<I',b[80:84])[0]
    a=np.frombuffer(b[84:84+50*n],dtype=np.dtype([('n','<f4',3),('v','<f4',(3,3)),('a','<u2')]))
    v=a['v'].reshape(-1,3).astype(np.float64)
    u,inv=np.unique(v,axis=0,return_inverse=True)
    return u,inv.reshape(-1,3).astype(np.int32)
v,f=read_stl(sys.argv[1])
tg=tetgen.TetGen(v,f)
nodes,elems=tg.tetrahedralize(switches=sys.argv[3])[:2]
print(nodes.shape,elems.shape)
out=sys.argv[2]
with open(out+'.node','w') as fh:
    fh.write(f"{len(nodes)} 3 0 0\n")
    for i,p in enumerate(nodes): fh.write(f"{i+1} {float(p[0])!r} {float(p[1])!r} {float(p[2])!r}\n")
with open(out+'.ele','w') as fh:
    fh.write(f"{len(elems)} 4 0\n")
    for i,e in enumerate(elems): fh.write(f"{i+1} {e[0]+1} {e[1]+1} {e[2]+1} {e[3]+1}\n")
