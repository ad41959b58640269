/*
 * foton_kernel.h: the C interface of foton's density-estimation kernel plugins.
 *
 * A kernel plugin is a shared library named libfoton_<something>.so (foton_<something>.dll on
 * Windows) placed on foton's plugin search path (--plugin-dir, FOTON_PLUGIN_PATH, or the
 * folder of the foton executable). It exports one symbol, `foton_kernel_plugin`, a
 * FotonKernelPlugin with the API version, the kernel's name and its radial profile w(t).
 *
 * foton checks the version, evaluates w on [0, 1] (at t = i / 4096) and refuses a kernel
 * that is negative or not finite anywhere there, and normalises w numerically so that it
 * integrates to one over the disc (surface estimates) and over the ball (volume estimates).
 * The profile therefore need not be normalised, and no plugin can break energy conservation.
 * Every weight w returns during a render is checked too: a NaN, infinite or negative one
 * makes the render fail with an error that names it.
 *
 * w must be a pure function: it is called from many threads at once.
 */
#ifndef FOTON_KERNEL_H
#define FOTON_KERNEL_H

#include <stdint.h>

#define FOTON_KERNEL_API_VERSION 1

typedef struct FotonKernelPlugin {
    /* FOTON_KERNEL_API_VERSION */
    uint32_t api_version;
    /* Name used in scene files: kernel = "<name>". */
    const char *name;
    /* Radial profile w(t), t = d / r in [0, 1]; finite and >= 0. */
    double (*weight)(double t);
} FotonKernelPlugin;

#if defined(_WIN32)
#define FOTON_KERNEL_EXPORT __declspec(dllexport)
#else
#define FOTON_KERNEL_EXPORT __attribute__((visibility("default")))
#endif

#endif
