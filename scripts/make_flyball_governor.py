# Writes examples/flyball_governor.json (run from the repository root): the IFToMM A05
# parameters, and the spindle speed and sleeve height at which the published 30 deg arm
# angle is the steady rotation (the amended potential's gradient, as in
# tests/test_spatial_examples.cpp).
import json, math
g=9.81; rho=3000.0
L=1.0; w=0.01; mr=rho*L*w*w        # rod 1.0 x 0.01 x 0.01
mb=5.0                              # point mass at the rod's end
ms=rho*0.1**3                       # slider 0.1^3
k=8e5; c=4e4; L0=0.5; e=0.05; alpha0=math.radians(30); s_pub=0.5
ma=mr+mb; dc=(mr*L/2+mb*L)/ma
Ixx=mr*(w*w+w*w)/12
Ip=mr*(L*L+w*w)/12+mr*(L/2-dc)**2+mb*(L-dc)**2
def Veff(a,s,Om):
    zc=1-dc*math.sin(a); xc=e+dc*math.cos(a)
    Iax=Ixx*math.sin(a)**2+Ip*math.cos(a)**2+ma*xc*xc
    dx=e+0.5*math.cos(a)-e; dz=1-0.5*math.sin(a)-s
    l=math.hypot(dx,dz)
    return 2*(ma*g*zc+0.5*k*(l-L0)**2-0.5*Om*Om*Iax)+ms*g*s
def grad(a,s,Om,h=1e-6):
    return ((Veff(a+h,s,Om)-Veff(a-h,s,Om))/(2*h),(Veff(a,s+h,Om)-Veff(a,s-h,Om))/(2*h))
# s* at alpha0: the sleeve's balance dV/ds = 0 (independent of Om), analytic Newton
a_=0.5; h_=1.0; ca=math.cos(alpha0); sa=math.sin(alpha0)
s=s_pub
for it in range(60):
    dz=h_-a_*sa-s; l=math.hypot(a_*ca,dz)
    f=-2*k*(l-L0)*dz/l+ms*g
    dl=-dz/l
    df=-2*k*(dl*dz/l+(l-L0)*(-1/l-dz*dl/l**2))
    s-=f/df
dz=h_-a_*sa-s; l=math.hypot(a_*ca,dz)
dlda=(a_*ca*(-a_*sa)+dz*(-a_*ca))/l
xc=e+dc*ca
Om2=(-2*ma*g*dc*ca+2*k*(l-L0)*dlda)/(2*(Ixx-Ip)*sa*ca-2*ma*xc*dc*sa)
Om=math.sqrt(Om2)
print("ma",ma,"dc",dc,"Ip",Ip,"ms",ms,"s*",s,"Om*",Om, grad(alpha0,s,Om))

def Ry(a): return [[math.cos(a),0,math.sin(a)],[0,1,0],[-math.sin(a),0,math.cos(a)]]
def mm(A,B): return [[sum(A[i][k]*B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
Rz=[[-1,0,0],[0,-1,0],[0,0,1]]
def body_arm(name,sign):
    A=Ry(alpha0) if sign>0 else mm(Rz,Ry(alpha0))
    piv=[sign*e,0,1.0]
    d=[A[0][0],A[1][0],A[2][0]]
    r=[piv[i]+dc*d[i] for i in range(3)]
    v=[-Om*r[1],Om*r[0],0]
    wb=[A[2][0]*Om,A[2][1]*Om,A[2][2]*Om]  # A^T ez * Om
    return {"name":name,"type":"rigid","mass":ma,"inertia":[Ixx,Ip,Ip],"position":r,"orientation":{"matrix":A},"velocity":v,"angular_velocity":wb}
bodies=[{"name":"spindle","type":"rigid","shape":{"type":"box","size":[w,w,L],"density":rho},"position":[0,0,L/2],"angular_velocity":[0,0,Om]},
 {"name":"sleeve","type":"rigid","shape":{"type":"box","size":[0.1,0.1,0.1],"density":rho},"position":[0,0,s],"angular_velocity":[0,0,Om]},
 body_arm("arm_right",1),body_arm("arm_left",-1)]
joints=[{"name":"bearing","type":"revolute","bodies":["ground","spindle"],"world":{"point":[0,0,0],"axis":[0,0,1]}},
 {"name":"sleeve_guide","type":"prismatic","bodies":["spindle","sleeve"],"world":{"point":[0,0,s],"axis":[0,0,1]}},
 {"name":"hinge_right","type":"revolute","bodies":["spindle","arm_right"],"world":{"point":[e,0,1.0],"axis":[0,1,0]}},
 {"name":"hinge_left","type":"revolute","bodies":["spindle","arm_left"],"world":{"point":[-e,0,1.0],"axis":[0,-1,0]}}]
forces=[{"name":"spring_right","type":"spring_damper","bodies":["sleeve","arm_right"],"points":[[e,0,0],[0.5-dc,0,0]],"stiffness":k,"damping":c,"free_length":L0},
 {"name":"spring_left","type":"spring_damper","bodies":["sleeve","arm_left"],"points":[[-e,0,0],[0.5-dc,0,0]],"stiffness":k,"damping":c,"free_length":L0}]
scene={"name":"Flyball governor with the parameters of IFToMM benchmark A05 (stiff flyball governor, library of computational benchmark problems, as published e.g. at rehabenggroup.github.io/MBSbenchmarksInOpenSim, A05: spindle and two arms 1.0 x 0.01 x 0.01 m, sleeve 0.1 m cube, density 3000 kg/m^3, 5 kg point masses at the arm ends, springs k = 8e5 N/m, c = 4e4 N s/m, free length 0.5 m between the arm midpoints and the sleeve's sides, arms 30 deg below the horizontal, sleeve at 0.5 m; our choices: hinges 0.05 m off the axis at the spindle top, the sleeve on a prismatic guide, the spindle driven at the constant speed %.6f rad/s at which that configuration is the steady rotation, the sleeve lowered by the springs' static stretch to %.12f m): it keeps turning steadily with the arms at 30 deg" % (Om, s),
 "dimension":3,"gravity":[0,0,-g],"bodies":bodies,"joints":joints,
 "drivers":[{"name":"motor","type":"joint_angle","joint":"bearing","law":{"type":"constant_speed","speed":Om}}],
 "forces":forces,"outputs":[{"type":"energy"}],
 "solver":{"t_end":2.0,"output_step":0.005,"rtol":1e-8,"atol":1e-10}}
json.dump(scene,open("examples/flyball_governor.json","w"),indent=2)
