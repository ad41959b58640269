/*
 * The Epanechnikov kernel, w(t) = 1 - t^2, as a foton kernel plugin: the kernel that
 * minimises the asymptotic mean integrated squared error of a density estimate.
 *
 * Build:  cc -shared -fPIC -O2 -I.. -o libfoton_epanechnikov.so epanechnikov.c
 * Use:    foton render SCENE --plugin-dir . --set integrators.photon.kernel=epanechnikov
 */
#include "foton_kernel.h"

static double epanechnikov(double t) { return 1.0 - t * t; }

FOTON_KERNEL_EXPORT const FotonKernelPlugin foton_kernel_plugin = {
    FOTON_KERNEL_API_VERSION,
    "epanechnikov",
    epanechnikov,
};
