"""A 2 x 2 x 1 box with one vertical edge rounded (radius 0.4), sampled uniformly by area with
Gaussian noise along the normal of SIGMA x the spacing sqrt(area / n): the fillet example of the
"scanner data" issue. Usage: python3 scripts/rounded-box.py SIGMA OUT.xyz (prints the spacing)."""
import random, math, sys
random.seed(5)
sig_rel=float(sys.argv[1]); out=sys.argv[2]
n=120000; r=0.4; c=(1.6,1.6)
A_top=4-(r*r-math.pi*r*r/4)
parts=[('top',A_top),('bot',A_top),('x0',2),('y0',2),('x2',1.6),('y2',1.6),('cyl',r*math.pi/2)]
tot=sum(a for _,a in parts); h=math.sqrt(tot/n); s=sig_rel*h
pts=[]
def inside(x,y):
    return not (x>c[0] and y>c[1] and (x-c[0])**2+(y-c[1])**2>r*r)
for name,a in parts:
    m=round(n*a/tot)
    k=0
    while k<m:
        g=random.gauss(0,s)
        if name in('top','bot'):
            x,y=random.uniform(0,2),random.uniform(0,2)
            if not inside(x,y): continue
            z=1 if name=='top' else 0; nz=1 if name=='top' else -1
            p=(x,y,z+g*nz)
        elif name=='x0': p=(0-g,random.uniform(0,2),random.uniform(0,1))
        elif name=='y0': p=(random.uniform(0,2),0-g,random.uniform(0,1))
        elif name=='x2': p=(2+g,random.uniform(0,1.6),random.uniform(0,1))
        elif name=='y2': p=(random.uniform(0,1.6),2+g,random.uniform(0,1))
        else:
            t=random.uniform(0,math.pi/2); rr=r+g
            p=(c[0]+rr*math.cos(t),c[1]+rr*math.sin(t),random.uniform(0,1))
        pts.append(p); k+=1
open(out,'w').write('\n'.join('%.7f %.7f %.7f'%p for p in pts)+'\n')
print(h)
