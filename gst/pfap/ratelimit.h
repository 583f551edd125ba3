/* SPDX-License-Identifier: LGPL-2.1-or-later */
// The rate limit of every per-item warning the plugins post.
#pragma once

#include <glib.h>

// Whether to warn at the `count`th occurrence (from 1) of a fault that may repeat: at the
// 1st, 2nd, 4th, 8th, ..., so a fault shows at once and a lasting one costs log2(n) messages
// instead of flooding the bus. The element counts every occurrence in its stats.
inline bool pfap_warn_at(guint64 count) { return count != 0 && (count & (count - 1)) == 0; }
