#!/usr/bin/env python3
# Reference values for tests/solver/brdf_test.cpp (MatchesLiteralValuesFromTheContractFormulas):
# CONTRACT.md §2 transcribed directly, with θh and φh as angles (acos/atan2). Prints S and f.
from math import *
def d(t,p):
    t,p=radians(t),radians(p); return (sin(t)*cos(p),sin(t)*sin(p),cos(t))
def spec(model,wo,wi,a,ax,ay):
    h=[wo[k]+wi[k] for k in range(3)]
    hh=sum(x*x for x in h); hn=h[2]
    th=acos(hn/sqrt(hh)); ph=atan2(h[1],h[0]); t2=tan(th)**2
    ci,co=wi[2],wo[2]
    if model=='ward': return exp(-t2/a**2)/(4*pi*a*a*sqrt(ci*co))
    if model=='ward_gmd': return hh/(pi*a*a*hn**4)*exp(-t2/a**2)
    if model=='ward_aniso': return exp(-t2*(cos(ph)**2/ax**2+sin(ph)**2/ay**2))/(4*pi*ax*ay*sqrt(ci*co))
    if model=='ward_gmd_aniso': return hh/(pi*ax*ay*hn**4)*exp(-((h[0]/ax)**2+(h[1]/ay)**2)/hn**2)
rd=(0.5,0.4,0.3); rs=(0.05,0.1,0.2)
for (wo,wi) in [((30,20),(40,215)),((60,0),(55,170)),((10,90),(80,-45))]:
  for m in ['ward','ward_gmd','ward_aniso','ward_gmd_aniso']:
    s=spec(m,d(*wo),d(*wi),0.2,0.15,0.3)
    print(wo,wi,m,'S=%.17g'%s,'f=',['%.17g'%(rd[c]/pi+rs[c]*s) for c in range(3)])
