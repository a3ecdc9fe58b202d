/* The two dynamic programmes' inner loops in C (optional: virja.plan.fastdp).
 *
 * hand_window: the whole of virja.plan.drums.solve over a window (every group's layer,
 * the beam and the way back) on C arrays, one call per window.
 * hand_layer: one layer of virja.plan.drums.solve (the loop over a layer's states and a
 * group's options), the same visiting order, the same sums in the same order, the same
 * strict "<" merge, so every result is the Python loop's to the bit.
 * bass_solve: the whole of virja.plan.bass.solve's Viterbi over hand states.
 *
 * Either returns None when its input is outside what it handles (the caller then runs
 * the Python loop).  Built in place by tools/build_dpcore.py (tools/setup.sh runs it);
 * compiled with -ffp-contract=off so that no a*b+c is fused (the Python loop rounds each
 * operation).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define DPCORE_VERSION 1
#define DPCORE_INFEASIBLE (-(1LL << 40)) /* virja.plan.drums._INFEASIBLE */
#ifndef DPCORE_SOURCE_DIGEST /* set by tools/build_dpcore.py: the digest of this file */
#define DPCORE_SOURCE_DIGEST ""
#endif

/* ---------------------------------------------------------------- helpers */

static int as_ll_list(PyObject *seq, Py_ssize_t n, long long *out) {
    for (Py_ssize_t i = 0; i < n; i++) {
        long long v = PyLong_AsLongLong(PySequence_Fast_GET_ITEM(seq, i));
        if (v == -1 && PyErr_Occurred()) return -1;
        out[i] = v;
    }
    return 0;
}

static int as_double_list(PyObject *seq, Py_ssize_t n, double *out) {
    for (Py_ssize_t i = 0; i < n; i++) {
        double v = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, i));
        if (v == -1.0 && PyErr_Occurred()) return -1;
        out[i] = v;
    }
    return 0;
}

/* ------------------------------------------------------------ hand_layer */

/* hand_layer(keys, accs, cur_rl, cur_lefts, row_costs, row_kept, right_kept, right_class,
 *            left_kept, left_class, steps, n_rl, n_lefts, n_next_rows, drop_k, drop_pen)
 * -> (keys, accs, codes) of the next layer in first-reached order, or None. */
/* A next layer's merge (hand_layer and hand_window): the key's first arrival is
 * numbered in order, a later one replaces it only when strictly cheaper (the Python
 * loop's order and strict <). */
static inline void layer_merge(int32_t *index, long long *out_keys, double *out_tot,
                               long long *out_came, Py_ssize_t *n_out, long long nkey,
                               double total, long long code) {
    int32_t at = index[nkey];
    if (at < 0) {
        index[nkey] = (int32_t)*n_out;
        out_keys[*n_out] = nkey;
        out_tot[*n_out] = total;
        out_came[*n_out] = total < INFINITY ? code : 0;
        (*n_out)++;
    } else if (total < out_tot[at]) {
        out_tot[at] = total;
        out_came[at] = code;
    }
}

static PyObject *hand_layer(PyObject *self, PyObject *args) {
    PyObject *keys_o, *accs_o, *row_costs_o, *row_kept_o, *right_kept_o, *right_class_o;
    PyObject *left_kept_o, *left_class_o, *steps_o;
    long long cur_rl, cur_lefts, n_rl, n_lefts, n_next_rows, drop_k;
    double drop_pen;
    if (!PyArg_ParseTuple(args, "OOLLOOOOOOOLLLLd", &keys_o, &accs_o, &cur_rl, &cur_lefts,
                          &row_costs_o, &row_kept_o, &right_kept_o, &right_class_o,
                          &left_kept_o, &left_class_o, &steps_o, &n_rl, &n_lefts,
                          &n_next_rows, &drop_k, &drop_pen))
        return NULL;
    if (!PyList_Check(keys_o) || !PyList_Check(accs_o) || !PyList_Check(row_costs_o) ||
        !PyList_Check(row_kept_o) || !PyList_Check(right_kept_o) ||
        !PyList_Check(right_class_o) || !PyList_Check(left_kept_o) ||
        !PyList_Check(left_class_o) || !PyList_Check(steps_o))
        Py_RETURN_NONE;
    Py_ssize_t n = PyList_GET_SIZE(keys_o);
    Py_ssize_t n_steps = PyList_GET_SIZE(steps_o);
    Py_ssize_t n_rows = PyList_GET_SIZE(row_costs_o);
    Py_ssize_t n_rh = PyList_GET_SIZE(right_kept_o), n_lh = PyList_GET_SIZE(left_kept_o);
    long long n_next = n_next_rows * n_rl;
    if (PyList_GET_SIZE(accs_o) != n || PyList_GET_SIZE(row_kept_o) != n_rows ||
        PyList_GET_SIZE(right_class_o) != n_rh || PyList_GET_SIZE(left_class_o) != n_lh ||
        cur_rl <= 0 || cur_lefts <= 0 || n_lefts <= 0 || n_next <= 0 || n_next > (1 << 24))
        Py_RETURN_NONE;

    PyObject *result = NULL;
    size_t cap = (size_t)n * (size_t)(n_steps + 1) + 1;
    long long *keys = malloc(sizeof(long long) * (size_t)(n + 1));
    double *accs = malloc(sizeof(double) * (size_t)(n + 1));
    long long *st_k = malloc(sizeof(long long) * (size_t)(n_steps + 1) * 5);
    long long *st_first = st_k + (n_steps + 1);
    long long *st_base = st_first + (n_steps + 1);
    long long *st_keeps = st_base + (n_steps + 1);
    long long *st_npens = st_keeps + (n_steps + 1);
    double *st_pair = malloc(sizeof(double) * (size_t)(n_steps + 1));
    PyObject **st_pens = malloc(sizeof(PyObject *) * (size_t)(n_steps + 1));
    long long *rkept = malloc(sizeof(long long) * (size_t)(n_rh + n_lh + n_rows + 1));
    long long *lkept = rkept + n_rh;
    long long *rowkept = lkept + n_lh;
    long long *rclass = malloc(sizeof(long long) * (size_t)((n_rh + n_lh) * n_steps + 1));
    long long *lclass = rclass + n_rh * n_steps;
    int32_t *index = malloc(sizeof(int32_t) * (size_t)n_next);
    long long *out_keys = malloc(sizeof(long long) * cap);
    double *out_tot = malloc(sizeof(double) * cap);
    long long *out_came = malloc(sizeof(long long) * cap);
    if (!keys || !accs || !st_k || !st_pair || !st_pens || !rkept || !rclass || !index ||
        !out_keys || !out_tot || !out_came) {
        PyErr_NoMemory();
        goto done;
    }
    if (as_ll_list(keys_o, n, keys) < 0 || as_double_list(accs_o, n, accs) < 0 ||
        as_ll_list(right_kept_o, n_rh, rkept) < 0 || as_ll_list(left_kept_o, n_lh, lkept) < 0 ||
        as_ll_list(row_kept_o, n_rows, rowkept) < 0)
        goto done;
    for (Py_ssize_t j = 0; j < n_steps; j++) {
        PyObject *st = PyList_GET_ITEM(steps_o, j);
        if (!PyTuple_Check(st) || PyTuple_GET_SIZE(st) != 6 ||
            !PyTuple_Check(PyTuple_GET_ITEM(st, 1))) {
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
        st_k[j] = PyLong_AsLongLong(PyTuple_GET_ITEM(st, 0));
        st_pens[j] = PyTuple_GET_ITEM(st, 1);
        st_npens[j] = PyTuple_GET_SIZE(st_pens[j]);
        st_first[j] = PyLong_AsLongLong(PyTuple_GET_ITEM(st, 2));
        st_pair[j] = PyFloat_AsDouble(PyTuple_GET_ITEM(st, 3));
        st_base[j] = PyLong_AsLongLong(PyTuple_GET_ITEM(st, 4));
        st_keeps[j] = PyLong_AsLongLong(PyTuple_GET_ITEM(st, 5));
        if (PyErr_Occurred()) goto done;
        if (st_keeps[j] < 0 || st_keeps[j] > 3 || st_first[j] < 0) {
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
    }
    for (int side = 0; side < 2; side++) {
        PyObject *cls_o = side ? left_class_o : right_class_o;
        Py_ssize_t m = side ? n_lh : n_rh;
        long long *cls = side ? lclass : rclass;
        for (Py_ssize_t i = 0; i < m; i++) {
            PyObject *row = PyList_GET_ITEM(cls_o, i);
            if (!PyList_Check(row) || PyList_GET_SIZE(row) != n_steps) {
                result = Py_None;
                Py_INCREF(result);
                goto done;
            }
            if (as_ll_list(row, n_steps, cls + i * n_steps) < 0) goto done;
        }
    }
    for (long long i = 0; i < n_next; i++) index[i] = -1;

    Py_ssize_t n_out = 0;
    long long n_options = drop_k + 1;
    for (Py_ssize_t sid = 0; sid < n; sid++) {
        long long key = keys[sid];
        double acc = accs[sid];
        long long ri = key / cur_rl, hands = key % cur_rl;
        long long rh = hands / cur_lefts, lh = hands % cur_lefts;
        if (key < 0 || ri >= n_rows || rh >= n_rh || lh >= n_lh) {
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
        PyObject *row = PyList_GET_ITEM(row_costs_o, ri);
        if (!PyTuple_Check(row)) {
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
        Py_ssize_t row_len = PyTuple_GET_SIZE(row);
        long long keep_r = rkept[rh] * n_lefts, keep_l = lkept[lh];
        long long kept_keys[4] = {0, keep_r, keep_l, keep_r + keep_l};
        long long here = sid * n_options;
        const long long *rc = rclass + rh * n_steps, *lc = lclass + lh * n_steps;
        for (Py_ssize_t j = 0; j <= n_steps; j++) {
            long long nkey, code;
            double total;
            if (j < n_steps) {
                long long c = rc[j] + lc[j];
                if (c < 0) continue;
                if (c >= st_npens[j] || st_first[j] >= row_len) {
                    result = Py_None;
                    Py_INCREF(result);
                    goto done;
                }
                nkey = st_base[j] + kept_keys[st_keeps[j]];
                double pen = PyFloat_AsDouble(PyTuple_GET_ITEM(st_pens[j], c));
                double first = PyFloat_AsDouble(PyTuple_GET_ITEM(row, st_first[j]));
                if (PyErr_Occurred()) goto done;
                total = acc + pen;
                total = total + first;
                total = total + st_pair[j];
                code = here + st_k[j];
            } else {  /* dropping every stroke: the row and hands as kept */
                nkey = rowkept[ri] * n_rl + kept_keys[3];
                total = acc + drop_pen;
                code = here + drop_k;
            }
            if (nkey < 0 || nkey >= n_next) {
                result = Py_None;
                Py_INCREF(result);
                goto done;
            }
            layer_merge(index, out_keys, out_tot, out_came, &n_out, nkey, total, code);
        }
    }
    PyObject *ok = PyList_New(n_out), *oa = PyList_New(n_out), *oc = PyList_New(n_out);
    if (!ok || !oa || !oc) {
        Py_XDECREF(ok);
        Py_XDECREF(oa);
        Py_XDECREF(oc);
        goto done;
    }
    for (Py_ssize_t i = 0; i < n_out; i++) {
        PyList_SET_ITEM(ok, i, PyLong_FromLongLong(out_keys[i]));
        PyList_SET_ITEM(oa, i, PyFloat_FromDouble(out_tot[i]));
        PyList_SET_ITEM(oc, i, PyLong_FromLongLong(out_came[i]));
    }
    result = PyTuple_Pack(3, ok, oa, oc);
    Py_DECREF(ok);
    Py_DECREF(oa);
    Py_DECREF(oc);
done:
    free(keys);
    free(accs);
    free(st_k);
    free(st_pair);
    free(st_pens);
    free(rkept);
    free(rclass);
    free(index);
    free(out_keys);
    free(out_tot);
    free(out_came);
    return result;
}


/* ------------------------------------------------------------ hand_parts */

/* hand_parts(parts, t, max_interval, next_parts, plays) -> (kept, classes) or None:
 * virja.plan.drums._hand_parts, the same comparisons in the same order. */
static PyObject *hand_parts(PyObject *self, PyObject *args) {
    PyObject *parts, *next_parts, *plays;
    double t, max_interval;
    if (!PyArg_ParseTuple(args, "OddOO", &parts, &t, &max_interval, &next_parts, &plays))
        return NULL;
    if (!PyList_Check(parts) || !PyDict_CheckExact(next_parts) || !PyTuple_Check(plays))
        Py_RETURN_NONE;
    Py_ssize_t n = PyList_GET_SIZE(parts), n_plays = PyTuple_GET_SIZE(plays);
    double dts[64];
    PyObject *reach[64], *classed[64];
    if (n_plays > 64) Py_RETURN_NONE;
    for (Py_ssize_t j = 0; j < n_plays; j++) {
        PyObject *p = PyTuple_GET_ITEM(plays, j);
        if (!PyTuple_Check(p) || PyTuple_GET_SIZE(p) != 3 ||
            !PyFloat_CheckExact(PyTuple_GET_ITEM(p, 0)) ||
            !PyDict_CheckExact(PyTuple_GET_ITEM(p, 1)) ||
            !PyDict_CheckExact(PyTuple_GET_ITEM(p, 2)))
            Py_RETURN_NONE;
        dts[j] = PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(p, 0));
        reach[j] = PyTuple_GET_ITEM(p, 1);
        classed[j] = PyTuple_GET_ITEM(p, 2);
    }
    /* check every part first: (None, piece) or (float, piece) */
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *part = PyList_GET_ITEM(parts, i);
        if (!PyTuple_CheckExact(part) || PyTuple_GET_SIZE(part) != 2) Py_RETURN_NONE;
        PyObject *last = PyTuple_GET_ITEM(part, 0);
        if (last != Py_None && !PyFloat_CheckExact(last)) Py_RETURN_NONE;
    }
    PyObject *kept = PyList_New(n), *classes = PyList_New(n);
    if (!kept || !classes) goto fail;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *part = PyList_GET_ITEM(parts, i);
        PyObject *last = PyTuple_GET_ITEM(part, 0), *piece = PyTuple_GET_ITEM(part, 1);
        double since;
        PyObject *key = part;
        Py_INCREF(key);
        if (last == Py_None) {
            since = INFINITY;
        } else {
            since = t - PyFloat_AS_DOUBLE(last);
            if (since >= max_interval) {
                Py_DECREF(key);
                key = PyTuple_Pack(2, Py_None, Py_None);
                if (!key) goto fail;
            }
        }
        PyObject *number = PyDict_GetItemWithError(next_parts, key);
        if (number == NULL) {
            if (PyErr_Occurred()) {
                Py_DECREF(key);
                goto fail;
            }
            number = PyLong_FromSsize_t(PyDict_GET_SIZE(next_parts));
            if (!number || PyDict_SetItem(next_parts, key, number) < 0) {
                Py_XDECREF(number);
                Py_DECREF(key);
                goto fail;
            }
        } else {
            Py_INCREF(number);
        }
        Py_DECREF(key);
        PyList_SET_ITEM(kept, i, number);
        PyObject *row = PyList_New(n_plays);
        if (!row) goto fail;
        PyList_SET_ITEM(classes, i, row);
        for (Py_ssize_t j = 0; j < n_plays; j++) {
            double x = since + dts[j];
            PyObject *need = PyDict_GetItemWithError(reach[j], piece);
            PyObject *cl = need ? PyDict_GetItemWithError(classed[j], piece) : NULL;
            if (!need || !cl || !PyFloat_CheckExact(need) || !PyTuple_Check(cl) ||
                PyTuple_GET_SIZE(cl) != 2 || !PyFloat_CheckExact(PyTuple_GET_ITEM(cl, 0)) ||
                !PyTuple_Check(PyTuple_GET_ITEM(cl, 1))) {
                if (!PyErr_Occurred()) {
                    Py_DECREF(kept);
                    Py_DECREF(classes);
                    /* next_parts may hold some of the parts now, numbered in the
                     * order the Python loop numbers them: it starts over and finds
                     * them so */
                    Py_RETURN_NONE;
                }
                goto fail;
            }
            PyObject *c_obj = NULL;
            if (x < PyFloat_AS_DOUBLE(need)) {
                c_obj = PyLong_FromLongLong(DPCORE_INFEASIBLE);
            } else {
                PyObject *steps = PyTuple_GET_ITEM(cl, 1);
                if (x < PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(cl, 0))) {
                    for (Py_ssize_t q = 0; q < PyTuple_GET_SIZE(steps); q++) {
                        PyObject *st = PyTuple_GET_ITEM(steps, q);
                        double time = PyFloat_AsDouble(PyTuple_GET_ITEM(st, 0));
                        if (time == -1.0 && PyErr_Occurred()) goto fail;
                        if (x < time) {
                            c_obj = PyTuple_GET_ITEM(st, 1);
                            Py_INCREF(c_obj);
                            break;
                        }
                    }
                }
                if (!c_obj) c_obj = PyLong_FromLong(0);
            }
            if (!c_obj) goto fail;
            PyList_SET_ITEM(row, j, c_obj);
        }
    }
    {
        PyObject *res = PyTuple_Pack(2, kept, classes);
        Py_DECREF(kept);
        Py_DECREF(classes);
        return res;
    }
fail:
    Py_XDECREF(kept);
    Py_XDECREF(classes);
    return NULL;
}


/* ------------------------------------------------------------ hand_step */

/* setdefault(d, key, len(d)) -> the number (a new reference), NULL on error */
static PyObject *number_of(PyObject *d, PyObject *key) {
    PyObject *number = PyDict_GetItemWithError(d, key);
    if (number) {
        Py_INCREF(number);
        return number;
    }
    if (PyErr_Occurred()) return NULL;
    number = PyLong_FromSsize_t(PyDict_GET_SIZE(d));
    if (number && PyDict_SetItem(d, key, number) < 0) {
        Py_DECREF(number);
        return NULL;
    }
    return number;
}

/* the number of the part (time t + dt, piece) a played hand makes, or of (None, None)
 * when it is forgotten at once (as virja.plan.drums.solve): a new reference */
static PyObject *made_part(PyObject *d, double t, double dt, double max_interval,
                           PyObject *piece) {
    double at = t + dt;
    PyObject *key;
    if (t - at >= max_interval) {
        key = PyTuple_Pack(2, Py_None, Py_None);
    } else {
        PyObject *f = PyFloat_FromDouble(at);
        if (!f) return NULL;
        key = PyTuple_Pack(2, f, piece);
        Py_DECREF(f);
    }
    if (!key) return NULL;
    PyObject *number = number_of(d, key);
    Py_DECREF(key);
    return number;
}

/* hand_step(rows, rights, lefts, keys, accs, t, max_interval, rest_s, table, none_row,
 *           played, pens, right_plays, left_plays, drop_k, drop_pen)
 * -> (next rows, next rights, next lefts, keys, accs, codes) or None: one group of
 * virja.plan.drums.solve, from the layer's parts to the next layer (the beam aside). */
static PyObject *hand_step(PyObject *self, PyObject *args) {
    PyObject *rows, *rights, *lefts, *keys, *accs, *t_o, *table, *none_row, *played, *pens;
    PyObject *right_plays, *left_plays, *drop_pen_o;
    double max_interval, rest_s;
    long long drop_k;
    if (!PyArg_ParseTuple(args, "OOOOOOddOOOOOOLO", &rows, &rights, &lefts, &keys, &accs,
                          &t_o, &max_interval, &rest_s, &table, &none_row, &played, &pens,
                          &right_plays, &left_plays, &drop_k, &drop_pen_o))
        return NULL;
    if (!PyList_Check(rows) || !PyList_Check(rights) || !PyList_Check(lefts) ||
        !PyFloat_CheckExact(t_o) || !PyTuple_Check(table) || !PyTuple_Check(none_row) ||
        !PyTuple_Check(played) || !PyTuple_Check(pens) ||
        PyTuple_GET_SIZE(pens) != PyTuple_GET_SIZE(played))
        Py_RETURN_NONE;
    double t = PyFloat_AS_DOUBLE(t_o);
    Py_ssize_t n_rows = PyList_GET_SIZE(rows), n_played = PyTuple_GET_SIZE(played);
    Py_ssize_t n_table = PyTuple_GET_SIZE(table);
    for (Py_ssize_t i = 0; i < n_rows; i++) {
        PyObject *row = PyList_GET_ITEM(rows, i);
        if (!PyTuple_CheckExact(row) || PyTuple_GET_SIZE(row) != 2) Py_RETURN_NONE;
        PyObject *prev = PyTuple_GET_ITEM(row, 0), *prev_t = PyTuple_GET_ITEM(row, 1);
        if ((prev != Py_None && !PyLong_CheckExact(prev)) ||
            (prev_t != Py_None && !PyFloat_CheckExact(prev_t)))
            Py_RETURN_NONE;
    }
    for (Py_ssize_t j = 0; j < n_played; j++) {
        PyObject *op = PyTuple_GET_ITEM(played, j);
        if (!PyTuple_Check(op) || PyTuple_GET_SIZE(op) != 13 ||
            !PyFloat_Check(PyTuple_GET_ITEM(op, 2)) || !PyFloat_Check(PyTuple_GET_ITEM(op, 6)))
            Py_RETURN_NONE;
    }
    PyObject *result = NULL, *next_rows = NULL, *next_rights = NULL, *next_lefts = NULL;
    PyObject *row_costs = NULL, *row_kept = NULL, *r_parts = NULL, *l_parts = NULL;
    PyObject *steps = NULL, *merged = NULL, *none_key = NULL, *call = NULL;
    next_rows = PyDict_New();
    next_rights = PyDict_New();
    next_lefts = PyDict_New();
    row_costs = PyList_New(n_rows);
    row_kept = PyList_New(n_rows);
    none_key = PyTuple_Pack(2, Py_None, Py_None);
    if (!next_rows || !next_rights || !next_lefts || !row_costs || !row_kept || !none_key)
        goto done;
    for (Py_ssize_t i = 0; i < n_rows; i++) {
        PyObject *row = PyList_GET_ITEM(rows, i);
        PyObject *prev = PyTuple_GET_ITEM(row, 0), *prev_t = PyTuple_GET_ITEM(row, 1);
        PyObject *cost_row = none_row, *key = row, *number;
        if (prev_t != Py_None && t - PyFloat_AS_DOUBLE(prev_t) >= rest_s) {
            key = none_key;
        } else if (prev != Py_None && prev_t != Py_None) {
            Py_ssize_t at = PyLong_AsSsize_t(prev);
            if (at == -1 && PyErr_Occurred()) goto done;
            if (at < 0 || at >= n_table) {
                result = Py_None;
                Py_INCREF(result);
                goto done;
            }
            cost_row = PyTuple_GET_ITEM(table, at);
        }
        number = number_of(next_rows, key);
        if (!number) goto done;
        Py_INCREF(cost_row);
        PyList_SET_ITEM(row_costs, i, cost_row);
        PyList_SET_ITEM(row_kept, i, number);
    }
    call = Py_BuildValue("(OddOO)", rights, t, max_interval, next_rights, right_plays);
    if (!call) goto done;
    r_parts = hand_parts(NULL, call);
    Py_CLEAR(call);
    if (!r_parts || r_parts == Py_None) {
        if (r_parts == Py_None) result = r_parts, r_parts = NULL;
        goto done;
    }
    call = Py_BuildValue("(OddOO)", lefts, t, max_interval, next_lefts, left_plays);
    if (!call) goto done;
    l_parts = hand_parts(NULL, call);
    Py_CLEAR(call);
    if (!l_parts || l_parts == Py_None) {
        if (l_parts == Py_None) result = l_parts, l_parts = NULL;
        goto done;
    }
    /* the parts each played option makes, then its step */
    Py_ssize_t made_n = n_played;
    long long *m_row = malloc(sizeof(long long) * (size_t)(3 * made_n + 1));
    if (!m_row) {
        PyErr_NoMemory();
        goto done;
    }
    long long *m_r = m_row + made_n, *m_l = m_r + made_n;
    for (Py_ssize_t j = 0; j < n_played; j++) {
        PyObject *op = PyTuple_GET_ITEM(played, j);
        PyObject *r_piece = PyTuple_GET_ITEM(op, 1), *l_piece = PyTuple_GET_ITEM(op, 5);
        m_r[j] = m_l[j] = -1;
        PyObject *num;
        if (r_piece != Py_None) {
            num = made_part(next_rights, t, PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(op, 2)),
                            max_interval, r_piece);
            if (!num) goto made_fail;
            m_r[j] = PyLong_AsLongLong(num);
            Py_DECREF(num);
        }
        if (l_piece != Py_None) {
            num = made_part(next_lefts, t, PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(op, 6)),
                            max_interval, l_piece);
            if (!num) goto made_fail;
            m_l[j] = PyLong_AsLongLong(num);
            Py_DECREF(num);
        }
        PyObject *key = PyTuple_Pack(2, PyTuple_GET_ITEM(op, 9), t_o);
        if (!key) goto made_fail;
        num = number_of(next_rows, key);
        Py_DECREF(key);
        if (!num) goto made_fail;
        m_row[j] = PyLong_AsLongLong(num);
        Py_DECREF(num);
    }
    long long n_rights = PyDict_GET_SIZE(next_rights), n_lefts = PyDict_GET_SIZE(next_lefts);
    long long n_rl = n_rights * n_lefts;
    steps = PyList_New(n_played);
    if (!steps) goto made_fail;
    for (Py_ssize_t j = 0; j < n_played; j++) {
        PyObject *op = PyTuple_GET_ITEM(played, j);
        long long base = m_row[j] * n_rl + (m_r[j] > 0 ? m_r[j] : 0) * n_lefts +
                         (m_l[j] > 0 ? m_l[j] : 0);
        long long keeps = (m_r[j] < 0) + 2 * (m_l[j] < 0);
        PyObject *st = Py_BuildValue("(OOOOLL)", PyTuple_GET_ITEM(op, 0),
                                     PyTuple_GET_ITEM(pens, j), PyTuple_GET_ITEM(op, 11),
                                     PyTuple_GET_ITEM(op, 12), base, keeps);
        if (!st) goto made_fail;
        PyList_SET_ITEM(steps, j, st);
    }
    free(m_row);
    m_row = NULL;
    long long cur_lefts = PyList_GET_SIZE(lefts);
    long long cur_rl = PyList_GET_SIZE(rights) * cur_lefts;
    call = Py_BuildValue("(OOLLOOOOOOOLLLLO)", keys, accs, cur_rl, cur_lefts, row_costs,
                         row_kept, PyTuple_GET_ITEM(r_parts, 0), PyTuple_GET_ITEM(r_parts, 1),
                         PyTuple_GET_ITEM(l_parts, 0), PyTuple_GET_ITEM(l_parts, 1), steps,
                         n_rl, n_lefts, (long long)PyDict_GET_SIZE(next_rows), drop_k,
                         drop_pen_o);
    if (!call) goto done;
    merged = hand_layer(NULL, call);
    Py_CLEAR(call);
    if (!merged || merged == Py_None) {
        if (merged == Py_None) result = merged, merged = NULL;
        goto done;
    }
    {
        PyObject *kr = PyDict_Keys(next_rows), *krt = PyDict_Keys(next_rights);
        PyObject *klt = PyDict_Keys(next_lefts);
        if (kr && krt && klt)
            result = PyTuple_Pack(6, kr, krt, klt, PyTuple_GET_ITEM(merged, 0),
                                  PyTuple_GET_ITEM(merged, 1), PyTuple_GET_ITEM(merged, 2));
        Py_XDECREF(kr);
        Py_XDECREF(krt);
        Py_XDECREF(klt);
    }
    goto done;
made_fail:
    free(m_row);
done:
    Py_XDECREF(next_rows);
    Py_XDECREF(next_rights);
    Py_XDECREF(next_lefts);
    Py_XDECREF(row_costs);
    Py_XDECREF(row_kept);
    Py_XDECREF(r_parts);
    Py_XDECREF(l_parts);
    Py_XDECREF(steps);
    Py_XDECREF(merged);
    Py_XDECREF(none_key);
    Py_XDECREF(call);
    return result;
}

/* ------------------------------------------------------------ hand_window */

/* A layer's part, as virja.plan.drums numbers them: a row (previous motion, -1 for
 * None, and its time) or a hand's last stroke (its time, and its piece numbered in
 * ``pieces``: 0 is None).  Two parts are the same when the Python tuples are equal. */
typedef struct {
    long long prev;
    int has_t;
    double t;
} WRow;

typedef struct {
    int has;
    double last;
    long long piece;
} WPart;

typedef struct {
    WRow *rows;
    WPart *rights, *lefts;
    long long *keys, *came;
    Py_ssize_t n_rows, n_rights, n_lefts, n;
    long long n_options;
} WLayer;

static Py_ssize_t row_number(WRow *rows, Py_ssize_t *n, WRow r) {
    for (Py_ssize_t i = 0; i < *n; i++)
        if (rows[i].prev == r.prev && rows[i].has_t == r.has_t && (!r.has_t || rows[i].t == r.t))
            return i;
    rows[*n] = r;
    return (*n)++;
}

static Py_ssize_t part_number(WPart *parts, Py_ssize_t *n, WPart p) {
    for (Py_ssize_t i = 0; i < *n; i++)
        if (parts[i].has == p.has && (!p.has || parts[i].last == p.last) &&
            parts[i].piece == p.piece)
            return i;
    parts[*n] = p;
    return (*n)++;
}

typedef struct {
    double cost;
    Py_ssize_t index;
} Ranked;

/* keep_best's order (virja.plan.bounds): by cost, ties by index (a stable sort) */
static int ranked_cmp(const void *a, const void *b) {
    const Ranked *x = a, *y = b;
    if (x->cost < y->cost) return -1;
    if (y->cost < x->cost) return 1;
    return (x->index > y->index) - (x->index < y->index);
}

/* a group's window data (virja.plan.drums._Compiled.native), as doubles:
 * [n_played, drop_k, drop_pen, n_pieces], then per played option (13 each): option
 * index, first motion, pair cost, last motion, right piece (-1: does not play), right
 * dt, left piece, left dt, offset of its penalties by class, their number, offset of
 * the right hand's block, of the left hand's, the right hand's class scale; then the
 * penalties; then the blocks (drums._block): per previous piece (4 each) reach, the
 * steps' largest time, offset of its steps from the block, their number; then the
 * steps (time, penalty number). */
#define W_HEAD 4
#define W_REC 13
#define W_NEED 4

static void free_layer(WLayer *l) {
    free(l->rows);
    free(l->rights);
    free(l->lefts);
    free(l->keys);
    free(l->came);
}

static PyObject *none_or_float(int has, double v) {
    if (!has) Py_RETURN_NONE;
    return PyFloat_FromDouble(v);
}

/* hand_window(start, times, natives, backs, table, n_cols, none_index, max_interval,
 *             rest_s, beam, pieces)
 * -> (option per group, per-stroke costs per group, state after each group, total) or
 * None: the whole of virja.plan.drums.solve over a window in C, on C arrays.
 * ``start``: (prev, prev_t, t_right, t_left, right piece, left piece) with pieces
 * numbered in ``pieces`` (0: None); ``natives[g]``: group g's window data (above) as a
 * buffer of doubles; ``backs[g]``: per option (number of strokes, (motion, stroke
 * index) of each played stroke, left hand first); ``table``: the cost table's rows as
 * one buffer of doubles, ``n_cols`` to a row; ``beam`` < 0: none.  The same parts
 * numbered in the same first-reached order, the same comparisons, sums in the same
 * order and the same strict "<" merge as the Python loop (drums._step, _hand_parts,
 * _merge_layer), keep_best's cut, and solve's way back. */
static PyObject *hand_window(PyObject *self, PyObject *args) {
    PyObject *start, *times, *natives, *backs, *table_o, *pieces;
    Py_ssize_t n_cols, none_index, beam;
    double max_interval, rest_s;
    if (!PyArg_ParseTuple(args, "OOOOOnnddnO", &start, &times, &natives, &backs, &table_o,
                          &n_cols, &none_index, &max_interval, &rest_s, &beam, &pieces))
        return NULL;
    if (!PyTuple_CheckExact(start) || PyTuple_GET_SIZE(start) != 6 || !PyList_Check(times) ||
        !PyList_Check(natives) || !PyList_Check(backs) || !PyTuple_Check(pieces) ||
        PyList_GET_SIZE(natives) != PyList_GET_SIZE(times) ||
        PyList_GET_SIZE(backs) != PyList_GET_SIZE(times) || n_cols <= 0)
        Py_RETURN_NONE;
    Py_ssize_t n_groups = PyList_GET_SIZE(times), n_pieces = PyTuple_GET_SIZE(pieces);
    for (Py_ssize_t g = 0; g < n_groups; g++) {
        PyObject *t = PyList_GET_ITEM(times, g);
        if (!PyFloat_CheckExact(t) || !isfinite(PyFloat_AS_DOUBLE(t))) Py_RETURN_NONE;
    }
    /* the start state's parts */
    WRow row0;
    WPart right0, left0;
    {
        PyObject *p = PyTuple_GET_ITEM(start, 0), *pt = PyTuple_GET_ITEM(start, 1);
        PyObject *tr = PyTuple_GET_ITEM(start, 2), *tl = PyTuple_GET_ITEM(start, 3);
        PyObject *pr = PyTuple_GET_ITEM(start, 4), *pl = PyTuple_GET_ITEM(start, 5);
        if ((p != Py_None && !PyLong_CheckExact(p)) ||
            (pt != Py_None && !PyFloat_CheckExact(pt)) ||
            (tr != Py_None && !PyFloat_CheckExact(tr)) ||
            (tl != Py_None && !PyFloat_CheckExact(tl)) || !PyLong_CheckExact(pr) ||
            !PyLong_CheckExact(pl))
            Py_RETURN_NONE;
        row0.prev = p == Py_None ? -1 : PyLong_AsLongLong(p);
        row0.has_t = pt != Py_None;
        row0.t = row0.has_t ? PyFloat_AS_DOUBLE(pt) : 0.0;
        right0.has = tr != Py_None;
        right0.last = right0.has ? PyFloat_AS_DOUBLE(tr) : 0.0;
        right0.piece = PyLong_AsLongLong(pr);
        left0.has = tl != Py_None;
        left0.last = left0.has ? PyFloat_AS_DOUBLE(tl) : 0.0;
        left0.piece = PyLong_AsLongLong(pl);
        if (PyErr_Occurred()) return NULL;
        if ((p != Py_None && row0.prev < 0) || (row0.has_t && !isfinite(row0.t)) ||
            (right0.has && !isfinite(right0.last)) || (left0.has && !isfinite(left0.last)) ||
            right0.piece < 0 || right0.piece >= n_pieces || left0.piece < 0 ||
            left0.piece >= n_pieces)
            Py_RETURN_NONE;
    }
    Py_buffer table_b;
    if (PyObject_GetBuffer(table_o, &table_b, PyBUF_SIMPLE) < 0) return NULL;
    const double *table = table_b.buf;
    Py_ssize_t n_trows = table_b.len / (Py_ssize_t)sizeof(double) / n_cols;
    PyObject *result = NULL, *ks = NULL, *pers = NULL, *states = NULL;
    Py_buffer *bufs = calloc((size_t)n_groups + 1, sizeof(Py_buffer));
    WLayer *layers = calloc((size_t)n_groups + 1, sizeof(WLayer));
    double *accs = NULL;
    Ranked *ranked = NULL;
    long long *rclass = NULL, *rkept = NULL, *m_row = NULL;
    int32_t *index = NULL;
    double *out_tot = NULL;
    long long *out_keys = NULL, *out_came = NULL;
    Py_ssize_t n_bufs = 0;
    int refused = 0;
    if (!bufs || !layers) {
        PyErr_NoMemory();
        goto done;
    }
    if (none_index < 0 || none_index >= n_trows) {
        refused = 1;
        goto done;
    }
    for (Py_ssize_t g = 0; g < n_groups; g++) {
        if (PyObject_GetBuffer(PyList_GET_ITEM(natives, g), &bufs[g], PyBUF_SIMPLE) < 0)
            goto done;
        n_bufs++;
    }
    /* the start layer: one state, key 0 */
    {
        WLayer *l = &layers[0];
        l->rows = malloc(sizeof(WRow));
        l->rights = malloc(sizeof(WPart));
        l->lefts = malloc(sizeof(WPart));
        l->keys = calloc(1, sizeof(long long));
        l->came = calloc(1, sizeof(long long));
        accs = malloc(sizeof(double));
        if (!l->rows || !l->rights || !l->lefts || !l->keys || !l->came || !accs) {
            PyErr_NoMemory();
            goto done;
        }
        l->rows[0] = row0;
        l->rights[0] = right0;
        l->lefts[0] = left0;
        l->n_rows = l->n_rights = l->n_lefts = l->n = 1;
        l->n_options = 1;
        accs[0] = 0.0;
    }
    for (Py_ssize_t g = 0; g < n_groups; g++) {
        const double *w = bufs[g].buf;
        Py_ssize_t w_len = bufs[g].len / (Py_ssize_t)sizeof(double);
        if (w_len < W_HEAD) {
            refused = 1;
            goto done;
        }
        Py_ssize_t n_played = (Py_ssize_t)w[0];
        long long drop_k = (long long)w[1];
        double drop_pen = w[2];
        Py_ssize_t wp = (Py_ssize_t)w[3];
        if (n_played < 0 || wp != n_pieces || w_len < W_HEAD + n_played * W_REC) {
            refused = 1;
            goto done;
        }
        const double *rec = w + W_HEAD;
        /* every block and its steps inside the data */
        for (Py_ssize_t j = 0; j < n_played; j++) {
            for (int side = 0; side < 2; side++) {
                Py_ssize_t boff = (Py_ssize_t)rec[j * W_REC + (side ? 11 : 10)];
                if (boff < 0 || boff + wp * W_NEED > w_len) {
                    refused = 1;
                    goto done;
                }
                for (Py_ssize_t q = 0; q < wp; q++) {
                    const double *nd = w + boff + q * W_NEED;
                    Py_ssize_t off = (Py_ssize_t)nd[2], cnt = (Py_ssize_t)nd[3];
                    if (off < 0 || cnt < 0 || boff + off + 2 * cnt > w_len) {
                        refused = 1;
                        goto done;
                    }
                }
            }
        }
        double t = PyFloat_AS_DOUBLE(PyList_GET_ITEM(times, g));
        WLayer *cur = &layers[g], *nxt = &layers[g + 1];
        Py_ssize_t n = cur->n;
        nxt->rows = malloc(sizeof(WRow) * (size_t)(cur->n_rows + n_played + 1));
        nxt->rights = malloc(sizeof(WPart) * (size_t)(cur->n_rights + n_played + 1));
        nxt->lefts = malloc(sizeof(WPart) * (size_t)(cur->n_lefts + n_played + 1));
        free(rclass);
        free(rkept);
        free(m_row);
        rclass = malloc(sizeof(long long) * (size_t)((cur->n_rights + cur->n_lefts) * n_played + 1));
        rkept = malloc(sizeof(long long) * (size_t)(cur->n_rights + cur->n_lefts + 2 * cur->n_rows + 1));
        m_row = malloc(sizeof(long long) * (size_t)(5 * n_played + 1));
        if (!nxt->rows || !nxt->rights || !nxt->lefts || !rclass || !rkept || !m_row) {
            PyErr_NoMemory();
            goto done;
        }
        long long *lclass = rclass + cur->n_rights * n_played;
        long long *lkept = rkept + cur->n_rights, *rowkept = lkept + cur->n_lefts;
        long long *rowcost = rowkept + cur->n_rows; /* the table row each row pays */
        long long *m_r = m_row + n_played, *m_l = m_r + n_played, *m_base = m_l + n_played;
        long long *m_keeps = m_base + n_played;
        /* the rows: kept, forgotten after a rest, and what their first motion pays */
        WRow none_row = {-1, 0, 0.0};
        for (Py_ssize_t i = 0; i < cur->n_rows; i++) {
            WRow r = cur->rows[i];
            if (r.has_t && t - r.t >= rest_s) {
                rowcost[i] = none_index;
                rowkept[i] = row_number(nxt->rows, &nxt->n_rows, none_row);
            } else {
                rowcost[i] = (r.prev >= 0 && r.has_t) ? r.prev : none_index;
                if (rowcost[i] >= n_trows) {
                    refused = 1;
                    goto done;
                }
                rowkept[i] = row_number(nxt->rows, &nxt->n_rows, r);
            }
        }
        /* each hand's parts: kept or forgotten, and the class per played option */
        for (int side = 0; side < 2; side++) {
            WPart *parts = side ? cur->lefts : cur->rights;
            Py_ssize_t m = side ? cur->n_lefts : cur->n_rights;
            WPart *next = side ? nxt->lefts : nxt->rights;
            Py_ssize_t *n_next = side ? &nxt->n_lefts : &nxt->n_rights;
            long long *kept = side ? lkept : rkept, *cls = side ? lclass : rclass;
            for (Py_ssize_t i = 0; i < m; i++) {
                WPart p = parts[i];
                double since;
                WPart keep = p;
                if (!p.has) {
                    since = INFINITY;
                } else {
                    since = t - p.last;
                    if (since >= max_interval) keep = (WPart){0, 0.0, 0};
                }
                kept[i] = part_number(next, n_next, keep);
                for (Py_ssize_t j = 0; j < n_played; j++) {
                    const double *o = rec + j * W_REC;
                    const double *blk = w + (Py_ssize_t)o[side ? 11 : 10];
                    const double *nd = blk + p.piece * W_NEED;
                    double x = since + o[side ? 7 : 5];
                    long long c = 0;
                    if (x < nd[0]) {
                        c = DPCORE_INFEASIBLE;
                    } else if (x < nd[1]) {
                        const double *st = blk + (Py_ssize_t)nd[2];
                        Py_ssize_t cnt = (Py_ssize_t)nd[3];
                        for (Py_ssize_t q = 0; q < cnt; q++) {
                            if (x < st[2 * q]) {
                                c = (long long)st[2 * q + 1] * (side ? 1 : (long long)o[12]);
                                break;
                            }
                        }
                    }
                    cls[i * n_played + j] = c;
                }
            }
        }
        /* the parts each played option makes, then its step */
        for (Py_ssize_t j = 0; j < n_played; j++) {
            const double *o = rec + j * W_REC;
            m_r[j] = m_l[j] = -1;
            for (int side = 0; side < 2; side++) {
                double piece = o[side ? 6 : 4];
                if (piece < 0) continue;
                double at = t + o[side ? 7 : 5];
                WPart made = {0, 0.0, 0};
                if (!(t - at >= max_interval)) made = (WPart){1, at, (long long)piece};
                if (made.piece < 0 || made.piece >= n_pieces) {
                    refused = 1;
                    goto done;
                }
                long long num = side ? part_number(nxt->lefts, &nxt->n_lefts, made)
                                     : part_number(nxt->rights, &nxt->n_rights, made);
                if (side)
                    m_l[j] = num;
                else
                    m_r[j] = num;
            }
            WRow made_row = {(long long)o[3], 1, t};
            m_row[j] = row_number(nxt->rows, &nxt->n_rows, made_row);
        }
        long long n_rl = (long long)nxt->n_rights * nxt->n_lefts, n_lefts = nxt->n_lefts;
        long long n_next = (long long)nxt->n_rows * n_rl;
        if (n_next <= 0 || n_next > (1 << 24)) {
            refused = 1;
            goto done;
        }
        for (Py_ssize_t j = 0; j < n_played; j++) {
            m_base[j] = m_row[j] * n_rl + (m_r[j] > 0 ? m_r[j] : 0) * n_lefts +
                        (m_l[j] > 0 ? m_l[j] : 0);
            m_keeps[j] = (m_r[j] < 0) + 2 * (m_l[j] < 0);
        }
        /* the merge (drums._merge_layer) */
        free(index);
        free(out_tot);
        free(out_keys);
        free(out_came);
        size_t cap = (size_t)n * (size_t)(n_played + 1) + 1;
        index = malloc(sizeof(int32_t) * (size_t)n_next);
        out_tot = malloc(sizeof(double) * cap);
        out_keys = malloc(sizeof(long long) * cap);
        out_came = malloc(sizeof(long long) * cap);
        if (!index || !out_tot || !out_keys || !out_came) {
            PyErr_NoMemory();
            goto done;
        }
        for (long long i = 0; i < n_next; i++) index[i] = -1;
        Py_ssize_t n_out = 0;
        long long n_options = drop_k + 1;
        long long cur_lefts = cur->n_lefts, cur_rl = (long long)cur->n_rights * cur_lefts;
        for (Py_ssize_t sid = 0; sid < n; sid++) {
            long long key = cur->keys[sid];
            double acc = accs[sid];
            long long ri = key / cur_rl, hands = key % cur_rl;
            long long rh = hands / cur_lefts, lh = hands % cur_lefts;
            const double *row = table + rowcost[ri] * n_cols;
            long long keep_r = rkept[rh] * n_lefts, keep_l = lkept[lh];
            long long kept_keys[4] = {0, keep_r, keep_l, keep_r + keep_l};
            long long here = sid * n_options;
            const long long *rc = rclass + rh * n_played, *lc = lclass + lh * n_played;
            for (Py_ssize_t j = 0; j <= n_played; j++) {
                long long nkey, code;
                double total;
                if (j < n_played) {
                    const double *o = rec + j * W_REC;
                    long long c = rc[j] + lc[j];
                    if (c < 0) continue;
                    long long first = (long long)o[1];
                    if (c >= (long long)o[9] || first < 0 || first >= n_cols ||
                        (Py_ssize_t)o[8] + c >= w_len) {
                        refused = 1;
                        goto done;
                    }
                    nkey = m_base[j] + kept_keys[m_keeps[j]];
                    total = acc + w[(Py_ssize_t)o[8] + c];
                    total = total + row[first];
                    total = total + o[2];
                    code = here + (long long)o[0];
                } else { /* dropping every stroke: the row and hands as kept */
                    nkey = rowkept[ri] * n_rl + kept_keys[3];
                    total = acc + drop_pen;
                    code = here + drop_k;
                }
                layer_merge(index, out_keys, out_tot, out_came, &n_out, nkey, total, code);
            }
        }
        /* the beam: the least-cost states, in their order (bounds.keep_best) */
        Py_ssize_t n_kept = n_out;
        if (beam >= 0 && n_out > beam) {
            free(ranked);
            ranked = malloc(sizeof(Ranked) * (size_t)n_out);
            if (!ranked) {
                PyErr_NoMemory();
                goto done;
            }
            for (Py_ssize_t i = 0; i < n_out; i++) {
                if (isnan(out_tot[i])) {
                    refused = 1;
                    goto done;
                }
                ranked[i].cost = out_tot[i];
                ranked[i].index = i;
            }
            qsort(ranked, (size_t)n_out, sizeof(Ranked), ranked_cmp);
            /* mark the kept ones, then take them in index order */
            for (Py_ssize_t i = 0; i < n_out; i++) index[out_keys[i]] = 0;
            for (Py_ssize_t i = 0; i < beam; i++) index[out_keys[ranked[i].index]] = 1;
            n_kept = 0;
            for (Py_ssize_t i = 0; i < n_out; i++) {
                if (index[out_keys[i]]) {
                    out_keys[n_kept] = out_keys[i];
                    out_tot[n_kept] = out_tot[i];
                    out_came[n_kept] = out_came[i];
                    n_kept++;
                }
            }
        }
        nxt->keys = malloc(sizeof(long long) * (size_t)(n_kept + 1));
        nxt->came = malloc(sizeof(long long) * (size_t)(n_kept + 1));
        double *nacc = malloc(sizeof(double) * (size_t)(n_kept + 1));
        if (!nxt->keys || !nxt->came || !nacc) {
            free(nacc);
            PyErr_NoMemory();
            goto done;
        }
        memcpy(nxt->keys, out_keys, sizeof(long long) * (size_t)n_kept);
        memcpy(nxt->came, out_came, sizeof(long long) * (size_t)n_kept);
        memcpy(nacc, out_tot, sizeof(double) * (size_t)n_kept);
        free(accs);
        accs = nacc;
        nxt->n = n_kept;
        nxt->n_options = n_options;
    }
    /* the first state (in layer order) of least objective */
    WLayer *last = &layers[n_groups];
    if (last->n == 0) {
        refused = 1;
        goto done;
    }
    Py_ssize_t end = 0;
    for (Py_ssize_t i = 1; i < last->n; i++)
        if (accs[i] < accs[end]) end = i;
    ks = PyList_New(n_groups);
    pers = PyList_New(n_groups);
    states = PyList_New(n_groups);
    if (!ks || !pers || !states) goto done;
    Py_ssize_t cur_id = end;
    for (Py_ssize_t g = n_groups - 1; g >= 0; g--) {
        WLayer *after = &layers[g + 1], *before = &layers[g];
        long long code = after->came[cur_id];
        Py_ssize_t prev_id = (Py_ssize_t)(code / after->n_options);
        Py_ssize_t k = (Py_ssize_t)(code % after->n_options);
        long long brl = (long long)before->n_rights * before->n_lefts;
        WRow brow = before->rows[before->keys[prev_id] / brl];
        Py_ssize_t r = none_index;
        if (brow.prev >= 0 && brow.has_t &&
            PyFloat_AS_DOUBLE(PyList_GET_ITEM(times, g)) - brow.t < rest_s)
            r = (Py_ssize_t)brow.prev;
        PyObject *back = PyList_GET_ITEM(backs, g);
        if (!PyTuple_Check(back) || k >= PyTuple_GET_SIZE(back)) {
            refused = 1;
            goto done;
        }
        PyObject *opt = PyTuple_GET_ITEM(back, k);
        if (!PyTuple_CheckExact(opt) || PyTuple_GET_SIZE(opt) < 1) {
            refused = 1;
            goto done;
        }
        Py_ssize_t n_strokes = PyLong_AsSsize_t(PyTuple_GET_ITEM(opt, 0));
        if (n_strokes < 0 || n_strokes > 8) {
            if (!PyErr_Occurred()) refused = 1;
            goto done;
        }
        double per[8] = {0.0};
        for (Py_ssize_t j = 1; j < PyTuple_GET_SIZE(opt); j++) {
            PyObject *pm = PyTuple_GET_ITEM(opt, j);
            if (!PyTuple_CheckExact(pm) || PyTuple_GET_SIZE(pm) != 2) {
                refused = 1;
                goto done;
            }
            Py_ssize_t m = PyLong_AsSsize_t(PyTuple_GET_ITEM(pm, 0));
            Py_ssize_t i = PyLong_AsSsize_t(PyTuple_GET_ITEM(pm, 1));
            if (PyErr_Occurred()) goto done;
            if (r < 0 || r >= n_trows || m < 0 || m >= n_cols || i < 0 || i >= n_strokes) {
                refused = 1;
                goto done;
            }
            per[i] = table[r * n_cols + m];
            r = m;
        }
        PyObject *pt = PyTuple_New(n_strokes);
        if (!pt) goto done;
        PyList_SET_ITEM(pers, g, pt);
        for (Py_ssize_t i = 0; i < n_strokes; i++) {
            PyObject *f = PyFloat_FromDouble(per[i]);
            if (!f) goto done;
            PyTuple_SET_ITEM(pt, i, f);
        }
        PyObject *kk = PyLong_FromSsize_t(k);
        if (!kk) goto done;
        PyList_SET_ITEM(ks, g, kk);
        long long key = after->keys[cur_id];
        long long arl = (long long)after->n_rights * after->n_lefts;
        WRow arow = after->rows[key / arl];
        WPart aright = after->rights[(key % arl) / after->n_lefts];
        WPart aleft = after->lefts[key % after->n_lefts];
        PyObject *st = Py_BuildValue(
            "(NNNNOO)",
            arow.prev >= 0 ? PyLong_FromLongLong(arow.prev) : (Py_INCREF(Py_None), Py_None),
            none_or_float(arow.has_t, arow.t), none_or_float(aright.has, aright.last),
            none_or_float(aleft.has, aleft.last), PyTuple_GET_ITEM(pieces, aright.piece),
            PyTuple_GET_ITEM(pieces, aleft.piece));
        if (!st) goto done;
        PyList_SET_ITEM(states, g, st);
        cur_id = prev_id;
    }
    result = Py_BuildValue("(OOON)", ks, pers, states, PyFloat_FromDouble(accs[end]));
done:
    if (refused && !result && !PyErr_Occurred()) {
        result = Py_None;
        Py_INCREF(result);
    }
    for (Py_ssize_t g = 0; g < n_bufs; g++) PyBuffer_Release(&bufs[g]);
    PyBuffer_Release(&table_b);
    if (layers)
        for (Py_ssize_t g = 0; g <= n_groups; g++) free_layer(&layers[g]);
    free(layers);
    free(bufs);
    free(accs);
    free(ranked);
    free(rclass);
    free(rkept);
    free(m_row);
    free(index);
    free(out_tot);
    free(out_keys);
    free(out_came);
    Py_XDECREF(ks);
    Py_XDECREF(pers);
    Py_XDECREF(states);
    return result;
}

/* ------------------------------------------------------------ bass_solve */

/* A bass state (string, fret, hand position) coded as one integer; -1: None. */
#define BASS_NONE (-1LL)
#define FIELD 4096LL

static int code_state(PyObject *st, long long *out) {
    if (st == Py_None) {
        *out = BASS_NONE;
        return 1;
    }
    if (!PyTuple_CheckExact(st) || PyTuple_GET_SIZE(st) != 3) return 0;
    long long v[3];
    for (int i = 0; i < 3; i++) {
        PyObject *x = PyTuple_GET_ITEM(st, i);
        if (!PyLong_CheckExact(x)) return 0;
        v[i] = PyLong_AsLongLong(x);
        if (v[i] < 0 || v[i] >= FIELD) {
            PyErr_Clear();
            return 0;
        }
    }
    *out = (v[0] * FIELD + v[1]) * FIELD + v[2];
    return 1;
}

static PyObject *state_of(long long code) {
    if (code == BASS_NONE) Py_RETURN_NONE;
    return Py_BuildValue("(LLL)", code / (FIELD * FIELD), (code / FIELD) % FIELD, code % FIELD);
}

typedef struct {
    long long a0, a1, melody, low, high;
    Py_ssize_t hs_at, n_hs; /* into the move arrays */
} BassOpt;

typedef struct {
    long long code; /* the state reached */
    double acc;
    long long prev; /* index of the state it came from in the previous layer */
    long long k;
    double c;
} BassEntry;

/* a small open-addressing map from state code to its entry in the layer */
typedef struct {
    long long *codes;
    int32_t *at;
    size_t mask;
} Map;

static int map_init(Map *m, size_t want) {
    size_t cap = 16;
    while (cap < 2 * want) cap <<= 1;
    m->codes = malloc(sizeof(long long) * cap);
    m->at = malloc(sizeof(int32_t) * cap);
    m->mask = cap - 1;
    if (!m->codes || !m->at) return -1;
    for (size_t i = 0; i < cap; i++) m->at[i] = -1;
    return 0;
}

static int32_t *map_slot(Map *m, long long code) {
    size_t h = (size_t)((unsigned long long)(code + 1) * 0x9E3779B97F4A7C15ULL >> 17) & m->mask;
    while (m->at[h] >= 0 && m->codes[h] != code) h = (h + 1) & m->mask;
    m->codes[h] = code;
    return &m->at[h];
}

static void map_free(Map *m) {
    free(m->codes);
    free(m->at);
}

/* merge a candidate into the layer being built (the dictionary's first-reached order,
 * replaced only by a strictly smaller total) */
static inline void bass_merge(Map *m, BassEntry *layer, Py_ssize_t *n, long long code,
                              double total, long long prev, long long k, double c) {
    int32_t *slot = map_slot(m, code);
    if (*slot < 0) {
        *slot = (int32_t)*n;
        BassEntry *e = &layer[(*n)++];
        e->code = code;
        e->acc = total;
        e->prev = prev;
        e->k = k;
        e->c = c;
    } else if (total < layer[*slot].acc) {
        BassEntry *e = &layer[*slot];
        e->acc = total;
        e->prev = prev;
        e->k = k;
        e->c = c;
    }
}

/* bass_solve(state, prepared, gaps, spans, shift_times, position_costs, shift_cost,
 *            shift_per_fret, rushed) -> (choice, costs, states, total) or None */
static PyObject *bass_solve(PyObject *self, PyObject *args) {
    PyObject *state_o, *prepared_o, *gaps_o, *spans_o, *shift_times_o, *pos_costs_o;
    double shift_cost, shift_per_fret, rushed;
    if (!PyArg_ParseTuple(args, "OOOOOOddd", &state_o, &prepared_o, &gaps_o, &spans_o,
                          &shift_times_o, &pos_costs_o, &shift_cost, &shift_per_fret, &rushed))
        return NULL;
    if (!PyList_Check(prepared_o) || !PyList_Check(spans_o) || !PyList_Check(shift_times_o) ||
        !PyList_Check(pos_costs_o))
        Py_RETURN_NONE;
    Py_ssize_t n_groups = PyList_GET_SIZE(prepared_o);
    Py_ssize_t n_top = PyList_GET_SIZE(spans_o);
    if (n_groups == 0 || PyList_GET_SIZE(shift_times_o) != n_top ||
        PyList_GET_SIZE(pos_costs_o) != n_top)
        Py_RETURN_NONE;
    long long start;
    if (!code_state(state_o, &start)) Py_RETURN_NONE;

    PyObject *result = NULL;
    long long *spans = malloc(sizeof(long long) * (size_t)n_top);
    double *shift_times = malloc(sizeof(double) * (size_t)n_top);
    double *pos_costs = malloc(sizeof(double) * (size_t)n_top);
    double *gaps = malloc(sizeof(double) * (size_t)n_groups);
    Py_ssize_t *opt_at = malloc(sizeof(Py_ssize_t) * (size_t)(n_groups + 1));
    Py_ssize_t *layer_at = malloc(sizeof(Py_ssize_t) * (size_t)(n_groups + 2));
    BassOpt *opts = NULL;
    long long *mv_h = NULL, *mv_state = NULL;
    double *mv_ph = NULL;
    BassEntry *entries = NULL;
    Map map = {NULL, NULL, 0};
    if (!spans || !shift_times || !pos_costs || !gaps || !opt_at || !layer_at) {
        PyErr_NoMemory();
        goto done;
    }
    if (as_ll_list(spans_o, n_top, spans) < 0 ||
        as_double_list(shift_times_o, n_top, shift_times) < 0 ||
        as_double_list(pos_costs_o, n_top, pos_costs) < 0)
        goto done;
    if (gaps_o == Py_None) {
        for (Py_ssize_t i = 0; i < n_groups; i++) gaps[i] = INFINITY;
    } else {
        PyObject *fast = PySequence_Fast(gaps_o, "gaps");
        if (!fast) goto done;
        if (PySequence_Fast_GET_SIZE(fast) < n_groups) {
            Py_DECREF(fast);
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
        int bad = as_double_list(fast, n_groups, gaps);
        Py_DECREF(fast);
        if (bad < 0) goto done;
    }
    /* count, then read every group's options and their moves */
    Py_ssize_t n_opts = 0, n_moves = 0;
    for (Py_ssize_t g = 0; g < n_groups; g++) {
        PyObject *grp = PyList_GET_ITEM(prepared_o, g);
        if (!PyList_Check(grp) || PyList_GET_SIZE(grp) == 0) {
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
        for (Py_ssize_t k = 0; k < PyList_GET_SIZE(grp); k++) {
            PyObject *op = PyList_GET_ITEM(grp, k);
            if (!PyTuple_Check(op) || PyTuple_GET_SIZE(op) != 6 ||
                !PyList_Check(PyTuple_GET_ITEM(op, 5))) {
                result = Py_None;
                Py_INCREF(result);
                goto done;
            }
            n_moves += PyList_GET_SIZE(PyTuple_GET_ITEM(op, 5));
        }
        n_opts += PyList_GET_SIZE(grp);
    }
    opts = malloc(sizeof(BassOpt) * (size_t)(n_opts + 1));
    mv_h = malloc(sizeof(long long) * (size_t)(n_moves + 1));
    mv_state = malloc(sizeof(long long) * (size_t)(n_moves + 1));
    mv_ph = malloc(sizeof(double) * (size_t)(n_moves + 1));
    if (!opts || !mv_h || !mv_state || !mv_ph) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t oi = 0, mi = 0;
    for (Py_ssize_t g = 0; g < n_groups; g++) {
        PyObject *grp = PyList_GET_ITEM(prepared_o, g);
        opt_at[g] = oi;
        for (Py_ssize_t k = 0; k < PyList_GET_SIZE(grp); k++, oi++) {
            PyObject *op = PyList_GET_ITEM(grp, k);
            BassOpt *o = &opts[oi];
            o->a0 = PyLong_AsLongLong(PyTuple_GET_ITEM(op, 0));
            o->a1 = PyLong_AsLongLong(PyTuple_GET_ITEM(op, 1));
            o->melody = PyLong_AsLongLong(PyTuple_GET_ITEM(op, 2));
            o->low = PyLong_AsLongLong(PyTuple_GET_ITEM(op, 3));
            o->high = PyLong_AsLongLong(PyTuple_GET_ITEM(op, 4));
            if (PyErr_Occurred()) goto done;
            PyObject *hs = PyTuple_GET_ITEM(op, 5);
            o->hs_at = mi;
            o->n_hs = PyList_GET_SIZE(hs);
            for (Py_ssize_t j = 0; j < o->n_hs; j++, mi++) {
                PyObject *mv = PyList_GET_ITEM(hs, j);
                if (!PyTuple_Check(mv) || PyTuple_GET_SIZE(mv) != 3 ||
                    !PyFloat_CheckExact(PyTuple_GET_ITEM(mv, 2)) ||
                    !code_state(PyTuple_GET_ITEM(mv, 1), &mv_state[mi]) ||
                    mv_state[mi] == BASS_NONE) {
                    if (PyErr_Occurred()) goto done;
                    result = Py_None;
                    Py_INCREF(result);
                    goto done;
                }
                mv_h[mi] = PyLong_AsLongLong(PyTuple_GET_ITEM(mv, 0));
                mv_ph[mi] = PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(mv, 2));
                if (PyErr_Occurred()) goto done;
            }
        }
    }
    opt_at[n_groups] = oi;

    /* the layers, one after another in ``entries``: layer g+1 (after group g) at
     * layer_at[g + 1]; layer 0 is the start state */
    size_t cap = 64, used = 1;
    entries = malloc(sizeof(BassEntry) * cap);
    if (!entries) {
        PyErr_NoMemory();
        goto done;
    }
    entries[0] = (BassEntry){start, 0.0, -1, -1, 0.0};
    layer_at[0] = 0;
    layer_at[1] = 1;
    for (Py_ssize_t g = 0; g < n_groups; g++) {
        Py_ssize_t from = layer_at[g], to = layer_at[g + 1];
        double gap = gaps[g];
        size_t per_state = 0;
        for (Py_ssize_t k = opt_at[g]; k < opt_at[g + 1]; k++)
            per_state += opts[k].n_hs > 0 ? (size_t)opts[k].n_hs : 1;
        size_t bound = per_state * (size_t)(to - from);
        if (used + bound > cap) {
            while (used + bound > cap) cap *= 2;
            BassEntry *grown = realloc(entries, sizeof(BassEntry) * cap);
            if (!grown) {
                PyErr_NoMemory();
                goto done;
            }
            entries = grown;
        }
        map_free(&map);
        map.codes = NULL;
        map.at = NULL;
        if (map_init(&map, bound) < 0) {
            PyErr_NoMemory();
            goto done;
        }
        BassEntry *layer = entries + to;
        Py_ssize_t n = 0;
        for (Py_ssize_t p = from; p < to; p++) {
            long long prev = entries[p].code;
            double acc = entries[p].acc;
            long long pid = p - from;
            if (prev == BASS_NONE) {
                for (Py_ssize_t k = opt_at[g]; k < opt_at[g + 1]; k++) {
                    BassOpt *o = &opts[k];
                    long long kk = k - opt_at[g];
                    if (o->a0 < 0) {
                        bass_merge(&map, layer, &n, BASS_NONE, acc + 0.0, pid, kk, 0.0);
                    } else {
                        for (Py_ssize_t j = o->hs_at; j < o->hs_at + o->n_hs; j++)
                            bass_merge(&map, layer, &n, mv_state[j], acc + mv_ph[j], pid, kk,
                                       mv_ph[j]);
                    }
                }
                continue;
            }
            long long s0 = prev / (FIELD * FIELD), f0 = (prev / FIELD) % FIELD, h0 = prev % FIELD;
            if (h0 >= n_top) {
                PyErr_SetString(PyExc_IndexError, "list index out of range");
                goto done;
            }
            long long in_reach = h0 + spans[h0];
            for (Py_ssize_t k = opt_at[g]; k < opt_at[g + 1]; k++) {
                BassOpt *o = &opts[k];
                long long kk = k - opt_at[g];
                double c;
                long long reached;
                if (o->a0 < 0) {
                    c = (double)llabs(o->melody - s0);
                    reached = prev;
                } else if (h0 <= o->low && o->high <= in_reach) {
                    c = (double)(llabs(o->a1 - f0) + llabs(o->a0 - s0)) + pos_costs[h0];
                    reached = (o->a0 * FIELD + o->a1) * FIELD + h0;
                    if (o->a0 >= FIELD || o->a1 >= FIELD || o->a1 < 0) {
                        result = Py_None;
                        Py_INCREF(result);
                        goto done;
                    }
                } else {
                    double base = (double)(llabs(o->a1 - f0) + llabs(o->a0 - s0));
                    for (Py_ssize_t j = o->hs_at; j < o->hs_at + o->n_hs; j++) {
                        long long d = llabs(mv_h[j] - h0);
                        if (d >= n_top) {
                            PyErr_SetString(PyExc_IndexError, "list index out of range");
                            goto done;
                        }
                        double cj = base + shift_cost;
                        cj = cj + shift_per_fret * (double)d;
                        cj = cj + mv_ph[j];
                        if (gap < shift_times[d]) cj += rushed;
                        bass_merge(&map, layer, &n, mv_state[j], acc + cj, pid, kk, cj);
                    }
                    continue;
                }
                bass_merge(&map, layer, &n, reached, acc + c, pid, kk, c);
            }
        }
        if (n == 0) {
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
        used = (size_t)to + (size_t)n;
        layer_at[g + 2] = (Py_ssize_t)used;
    }
    /* the first end state of least total, then back through the layers */
    Py_ssize_t from = layer_at[n_groups], to = layer_at[n_groups + 1];
    Py_ssize_t end = from;
    for (Py_ssize_t i = from + 1; i < to; i++)
        if (entries[i].acc < entries[end].acc) end = i;
    double total = entries[end].acc;
    PyObject *choice = PyTuple_New(n_groups), *costs = PyTuple_New(n_groups);
    PyObject *states = PyTuple_New(n_groups);
    if (!choice || !costs || !states) {
        Py_XDECREF(choice);
        Py_XDECREF(costs);
        Py_XDECREF(states);
        goto done;
    }
    Py_ssize_t cur = end;
    for (Py_ssize_t g = n_groups - 1; g >= 0; g--) {
        BassEntry *e = &entries[cur];
        PyTuple_SET_ITEM(choice, g, PyLong_FromLongLong(e->k));
        PyTuple_SET_ITEM(costs, g, PyFloat_FromDouble(e->c));
        PyTuple_SET_ITEM(states, g, state_of(e->code));
        cur = layer_at[g] + (Py_ssize_t)e->prev;
    }
    result = Py_BuildValue("(NNNd)", choice, costs, states, total);
done:
    map_free(&map);
    free(spans);
    free(shift_times);
    free(pos_costs);
    free(gaps);
    free(opt_at);
    free(layer_at);
    free(opts);
    free(mv_h);
    free(mv_state);
    free(mv_ph);
    free(entries);
    return result;
}

static PyMethodDef methods[] = {
    {"hand_layer", hand_layer, METH_VARARGS, "One layer of the hand DP (virja.plan.drums)."},
    {"hand_parts", hand_parts, METH_VARARGS, "One hand's parts of a layer (virja.plan.drums)."},
    {"hand_step", hand_step, METH_VARARGS, "One group of the hand DP (virja.plan.drums)."},
    {"hand_window", hand_window, METH_VARARGS, "A window of the hand DP (virja.plan.drums)."},
    {"bass_solve", bass_solve, METH_VARARGS, "The bass DP (virja.plan.bass.solve)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_dpcore", "The planner's DP inner loops in C.", -1, methods,
};

PyMODINIT_FUNC PyInit__dpcore(void) {
    PyObject *m = PyModule_Create(&module);
    if (m && (PyModule_AddIntConstant(m, "VERSION", DPCORE_VERSION) < 0 ||
              PyModule_AddStringConstant(m, "SOURCE_DIGEST", DPCORE_SOURCE_DIGEST) < 0)) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
