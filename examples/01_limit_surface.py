"""Example 1 (Python): limit-surface values and CoR estimates. Pair: 01_limit_surface.cpp."""

import numpy as np

import lugrip

ls = lugrip.LimitSurface(k=4.0)  # the paper's xi = 0.6354
print(f"xi(4) = {ls.xi:.6f}")
c = np.array([0.0, 0.5, 1.0, 1.5, 10.0])
for ci, f, t in zip(c, ls.ft_star(c), ls.tau_star(c)):
    print(f"c~ = {ci:5.2f}   f~* = {f:+.6f}   tau~* = {t:.6f}")

params = lugrip.ContactParams.preset("small_resin_block")
est = lugrip.estimate_cor(params, f_n=5.0, f_t=[1.20, 1.20, 0.0], tau=[-4.15e-3, 0.0, 1e-3])
c_tilde, inside = est
print("c~     :", np.round(c_tilde, 4))
print("inside :", inside)
print("status :", [lugrip.Status(s).name for s in est.status])
print("g [N mm]:", np.round(est.g * 1e3, 3))
