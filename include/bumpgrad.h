/* SPDX-License-Identifier: MIT */
/** @file bumpgrad.h  Umbrella header: the whole core API of bumpgrad. */
#ifndef BUMPGRAD_H
#define BUMPGRAD_H

#include "bumpgrad/common.h"
#include "bumpgrad/noise.h"
#include "bumpgrad/surfgrad.h"
#include "bumpgrad/framework.h"

#endif /* BUMPGRAD_H */
