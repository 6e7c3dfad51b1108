# Counts, on the 100-helix lattice of bench_stokeslet_sum (12 800 Gauss points, 6500 nodes), the
# near pairs and M2L translations of the uniform octree the FMM builds (root widths extent x 2^(k/16),
# depths 3 and 4) against a dual-tree traversal of an adaptive octree (leaves of at most q points)
# with the acceptance (r_A + r_B) < theta d, theta = 0.866 being the V list's worst case.
# Session 37 (docs/performance.md). Run: python3 docs/performance/experiments/dual_tree_count.py
import math, sys
rows=cols=10; nodes=65; R=0.01; pitch=0.05; L=0.2; sp=0.04
T=[]; S=[]
def at(base,z):
    phi=2*math.pi*z/pitch
    return (base[0]+R*math.cos(phi), base[1]+R*math.sin(phi), -z)
g=[0.5-0.5/math.sqrt(3),0.5+0.5/math.sqrt(3)]
for i in range(rows):
    for j in range(cols):
        b=(sp*i,sp*j)
        for k in range(nodes): T.append(at(b,L*k/(nodes-1)))
        for k in range(nodes-1):
            for a in g: S.append(at(b,L*(k+a)/(nodes-1)))
lo=[min(p[d] for p in S+T) for d in range(3)]; hi=[max(p[d] for p in S+T) for d in range(3)]
ext=max(hi[d]-lo[d] for d in range(3))
def uniform(width, depth):
    w=width/2**depth
    from collections import Counter
    cs=Counter(); ct=Counter()
    for p in S: cs[tuple(int((p[d]-lo[d])/w) for d in range(3))]+=1
    for p in T: ct[tuple(int((p[d]-lo[d])/w) for d in range(3))]+=1
    near=0; v=0
    occ=set(cs)
    for c,nt in ct.items():
        for dx in (-1,0,1):
            for dy in (-1,0,1):
                for dz in (-1,0,1):
                    near+=nt*cs.get((c[0]+dx,c[1]+dy,c[2]+dz),0)
        pc=tuple(x//2 for x in c)
        for ox in range(2*pc[0]-2,2*pc[0]+4):
            for oy in range(2*pc[1]-2,2*pc[1]+4):
                for oz in range(2*pc[2]-2,2*pc[2]+4):
                    if max(abs(ox-c[0]),abs(oy-c[1]),abs(oz-c[2]))>=2 and (ox,oy,oz) in occ: v+=1
    return near, v, len(ct)
for k in (0,4,8,12):
    wd=ext*2**(k/16)
    for depth in (3,4):
        n,v,b=uniform(wd,depth)
        print(f"uniform width {wd:.4f} depth {depth}: near {n/1e6:.2f}M  V-list M2L (leaf level) {v}  leaves {b}")
# dual tree
class Cell:
    __slots__=('c','h','s','t','kids')
def build(sidx,tidx,c,h,q):
    cell=Cell(); cell.c=c; cell.h=h; cell.s=sidx; cell.t=tidx; cell.kids=[]
    if len(sidx)+len(tidx)>q:
        parts={}
        for i in sidx:
            p=S[i]; key=tuple(int(p[d]>=c[d]) for d in range(3)); parts.setdefault(key,([],[]))[0].append(i)
        for i in tidx:
            p=T[i]; key=tuple(int(p[d]>=c[d]) for d in range(3)); parts.setdefault(key,([],[]))[1].append(i)
        for key,(ss,tt) in parts.items():
            cc=tuple(c[d]+(h/2 if key[d] else -h/2) for d in range(3))
            cell.kids.append(build(ss,tt,cc,h/2,q))
    return cell
root_c=tuple(lo[d]+ext/2 for d in range(3))
def dual(theta,q):
    root=build(list(range(len(S))),list(range(len(T))),root_c,ext/2*1.0001,q)
    p2p=0; m2l=0; sizes={}
    stack=[(root,root)]
    while stack:
        A,B=stack.pop()
        if not A.t or not B.s: continue
        d=math.dist(A.c,B.c); ra=math.sqrt(3)*A.h; rb=math.sqrt(3)*B.h
        if d>0 and (ra+rb)<theta*d:
            m2l+=1; r=round(math.log2(A.h/B.h)); sizes[r]=sizes.get(r,0)+1; continue
        if not A.kids and not B.kids:
            p2p+=len(A.t)*len(B.s); continue
        if B.kids and (not A.kids or B.h>=A.h):
            for k in B.kids: stack.append((A,k))
        else:
            for k in A.kids: stack.append((k,B))
    return p2p,m2l,sizes
for theta in (0.866,0.7):
    for q in (32,64,128,256):
        p,m,sz=dual(theta,q)
        print(f"dual theta {theta} q {q}: P2P {p/1e6:.2f}M  M2L {m}  size ratios {dict(sorted(sz.items()))}")
