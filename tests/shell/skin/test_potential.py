"""The total potential: its gradient and Hessian (elements plus the rank-one gas term) against
central differences, with point loads."""

import numpy as np

from ballenv.shell.skin import potential

from ..conftest import assemble_dense, central_gradient, central_jacobian, relative_error, small_model


def test_gradient_and_hessian_of_the_total_potential_match_central_differences():
    model, ws, x = small_model(subdivisions=1, pressure=2e4, gas_exponent=1.4)
    loads = np.random.default_rng(1).standard_normal(x.shape)

    def grad(y):
        out = np.zeros_like(y)
        potential.gradient(model, ws, y, loads, out)
        return out

    fd = central_gradient(lambda y: potential.energy(model, ws, y, loads), x)
    assert relative_error(grad(x), fd) < 1e-7
    s = potential.hessian(model, ws, x)
    assert s > 0
    u = ws.dvol.reshape(-1).copy()
    dense = assemble_dense(model.triangles, ws.tri_hess, len(x)) + assemble_dense(
        model.hinges, ws.hinge_hess, len(x)
    )
    dense += s * np.outer(u, u)
    assert relative_error(dense, central_jacobian(grad, x)) < 1e-7
