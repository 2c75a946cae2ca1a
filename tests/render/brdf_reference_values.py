#!/usr/bin/env python3
# Reference values for tests/render/brdf_test.cpp (MatchesLiteralValuesFromTheContractFormulas):
# docs/scene-format.md's models transcribed directly, with θh and φh as angles (acos/atan2). Prints
# S and f.
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
# The Fresnel-weighted models (solver/render/brdf.h): S of the plain model times Schlick's F over F0,
# written through the angle between wi and the normalised half vector; ior = 1.7.
def fresnel_weight(wo,wi,ior):
    h=[wo[k]+wi[k] for k in range(3)]; n=sqrt(sum(x*x for x in h))
    c=sum(wi[k]*h[k]/n for k in range(3)); f0=((ior-1)/(ior+1))**2
    return (f0+(1-f0)*(1-c)**5)/f0
for (wo,wi) in [((30,20),(40,215)),((60,0),(55,170)),((80,0),(75,180))]:
  for m in ['ward','ward_gmd','ward_aniso','ward_gmd_aniso']:
    s=spec(m,d(*wo),d(*wi),0.2,0.15,0.3)*fresnel_weight(d(*wo),d(*wi),1.7)
    print(wo,wi,m+'_fresnel','S*W=%.17g'%s,'f=',['%.17g'%(rd[c]/pi+rs[c]*s) for c in range(3)])
