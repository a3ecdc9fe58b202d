/* The two dynamic programmes' inner loops in C (optional: virja.plan.fastdp).
 *
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
            int32_t at = index[nkey];
            if (at < 0) {
                index[nkey] = (int32_t)n_out;
                out_keys[n_out] = nkey;
                out_tot[n_out] = total;
                out_came[n_out] = total < INFINITY ? code : 0;
                n_out++;
            } else if (total < out_tot[at]) {
                out_tot[at] = total;
                out_came[at] = code;
            }
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

static int index_cmp(const void *a, const void *b) {
    Py_ssize_t x = *(const Py_ssize_t *)a, y = *(const Py_ssize_t *)b;
    return (x > y) - (x < y);
}

/* virja.plan.bounds.keep_best applied to (keys, accs, codes): each replaced by the
 * ``beam`` entries of least cost in their order when there are more.  0 done, 1 refused
 * (a NaN cost: the Python loop decides), -1 error. */
static int keep_best_lists(PyObject **keys, PyObject **accs, PyObject **codes,
                           Py_ssize_t beam) {
    Py_ssize_t n = PyList_GET_SIZE(*accs);
    if (n <= beam) return 0;
    Ranked *r = malloc(sizeof(Ranked) * (size_t)n);
    Py_ssize_t *kept = malloc(sizeof(Py_ssize_t) * (size_t)(beam > 0 ? beam : 1));
    if (!r || !kept) {
        free(r);
        free(kept);
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *c = PyList_GET_ITEM(*accs, i);
        if (!PyFloat_CheckExact(c) || isnan(PyFloat_AS_DOUBLE(c))) {
            free(r);
            free(kept);
            return 1;
        }
        r[i].cost = PyFloat_AS_DOUBLE(c);
        r[i].index = i;
    }
    qsort(r, (size_t)n, sizeof(Ranked), ranked_cmp);
    for (Py_ssize_t i = 0; i < beam; i++) kept[i] = r[i].index;
    free(r);
    qsort(kept, (size_t)beam, sizeof(Py_ssize_t), index_cmp);
    PyObject **lists[3] = {keys, accs, codes};
    for (int l = 0; l < 3; l++) {
        PyObject *old = *lists[l], *out = PyList_New(beam);
        if (!out) {
            free(kept);
            return -1;
        }
        for (Py_ssize_t i = 0; i < beam; i++) {
            PyObject *v = PyList_GET_ITEM(old, kept[i]);
            Py_INCREF(v);
            PyList_SET_ITEM(out, i, v);
        }
        Py_DECREF(old);
        *lists[l] = out;
    }
    free(kept);
    return 0;
}

/* a layer's state i as its parts' numbers (virja.plan.drums._Layer.parts) */
static void layer_parts(PyObject *layer, Py_ssize_t i, Py_ssize_t *ri, Py_ssize_t *rh,
                        Py_ssize_t *lh) {
    Py_ssize_t n_r = PyList_GET_SIZE(PyTuple_GET_ITEM(layer, 1));
    Py_ssize_t n_l = PyList_GET_SIZE(PyTuple_GET_ITEM(layer, 2));
    Py_ssize_t key = PyLong_AsSsize_t(PyList_GET_ITEM(PyTuple_GET_ITEM(layer, 3), i));
    *ri = key / (n_r * n_l);
    *rh = (key % (n_r * n_l)) / n_l;
    *lh = key % n_l;
}

/* hand_window(rows, rights, lefts, times, groups, max_interval, rest_s, table, none_row,
 *             none_index, beam)
 * -> (option per group, per-stroke costs per group, state after each group, total) or
 * None: the whole of virja.plan.drums.solve over a window, from the start state's parts
 * (one row, one part per hand), each group ``groups[g]`` being _Compiled.window:
 * (played, pens, right_plays, left_plays, drop_k, drop_pen, back) where back[k] lists
 * option k's played strokes left hand first as (motion, stroke index), and
 * ``times[g]`` its time.  Each layer is hand_step's, cut by the beam (a negative beam:
 * none) as keep_best cuts it; the way back is solve's. */
static PyObject *hand_window(PyObject *self, PyObject *args) {
    PyObject *rows, *rights, *lefts, *times, *groups, *table, *none_row;
    double max_interval, rest_s;
    Py_ssize_t none_index, beam;
    if (!PyArg_ParseTuple(args, "OOOOOddOOnn", &rows, &rights, &lefts, &times, &groups,
                          &max_interval, &rest_s, &table, &none_row, &none_index, &beam))
        return NULL;
    if (!PyList_Check(times) || !PyList_Check(groups) ||
        PyList_GET_SIZE(times) != PyList_GET_SIZE(groups) || !PyTuple_Check(table) ||
        none_index < 0 || none_index >= PyTuple_GET_SIZE(table))
        Py_RETURN_NONE;
    Py_ssize_t n_groups = PyList_GET_SIZE(groups), n_table = PyTuple_GET_SIZE(table);
    for (Py_ssize_t g = 0; g < n_groups; g++) {
        PyObject *w = PyList_GET_ITEM(groups, g);
        if (!PyFloat_CheckExact(PyList_GET_ITEM(times, g)) || !PyTuple_CheckExact(w) ||
            PyTuple_GET_SIZE(w) != 7 || !PyTuple_CheckExact(PyTuple_GET_ITEM(w, 6)) ||
            !PyLong_CheckExact(PyTuple_GET_ITEM(w, 4)))
            Py_RETURN_NONE;
    }
    PyObject *result = NULL, *layers = NULL, *accs = NULL, *keys = NULL;
    PyObject *ks = NULL, *pers = NULL, *states = NULL;
    PyObject *mi = PyFloat_FromDouble(max_interval), *rs = PyFloat_FromDouble(rest_s);
    /* layers[g]: (rows, rights, lefts, keys, codes, n_options) after group g;
     * layers[0] the start */
    layers = PyList_New(0);
    accs = Py_BuildValue("[d]", 0.0);
    keys = Py_BuildValue("[n]", (Py_ssize_t)0);
    if (!layers || !accs || !keys || !mi || !rs) goto done;
    {
        PyObject *start = Py_BuildValue("(OOOOOn)", rows, rights, lefts, keys, keys,
                                        (Py_ssize_t)1);
        if (!start || PyList_Append(layers, start) < 0) {
            Py_XDECREF(start);
            goto done;
        }
        Py_DECREF(start);
    }
    for (Py_ssize_t g = 0; g < n_groups; g++) {
        PyObject *w = PyList_GET_ITEM(groups, g);
        PyObject *before = PyList_GET_ITEM(layers, g);
        PyObject *call = PyTuple_Pack(
            16, PyTuple_GET_ITEM(before, 0), PyTuple_GET_ITEM(before, 1),
            PyTuple_GET_ITEM(before, 2), keys, accs, PyList_GET_ITEM(times, g), mi, rs, table,
            none_row, PyTuple_GET_ITEM(w, 0), PyTuple_GET_ITEM(w, 1), PyTuple_GET_ITEM(w, 2),
            PyTuple_GET_ITEM(w, 3), PyTuple_GET_ITEM(w, 4), PyTuple_GET_ITEM(w, 5));
        if (!call) goto done;
        PyObject *stepped = hand_step(NULL, call);
        Py_DECREF(call);
        if (!stepped) goto done;
        if (stepped == Py_None) {
            result = stepped;
            goto done;
        }
        PyObject *nkeys = PyTuple_GET_ITEM(stepped, 3), *nacc = PyTuple_GET_ITEM(stepped, 4);
        PyObject *codes = PyTuple_GET_ITEM(stepped, 5);
        Py_INCREF(nkeys);
        Py_INCREF(nacc);
        Py_INCREF(codes);
        if (beam >= 0) {
            int cut = keep_best_lists(&nkeys, &nacc, &codes, beam);
            if (cut != 0) {
                Py_DECREF(nkeys);
                Py_DECREF(nacc);
                Py_DECREF(codes);
                Py_DECREF(stepped);
                if (cut > 0) {
                    result = Py_None;
                    Py_INCREF(result);
                }
                goto done;
            }
        }
        PyObject *layer = Py_BuildValue(
            "(OOONNn)", PyTuple_GET_ITEM(stepped, 0), PyTuple_GET_ITEM(stepped, 1),
            PyTuple_GET_ITEM(stepped, 2), nkeys, codes,
            PyLong_AsSsize_t(PyTuple_GET_ITEM(w, 4)) + 1);
        Py_DECREF(stepped);
        Py_SETREF(accs, nacc);
        if (!layer) goto done;
        Py_SETREF(keys, PyTuple_GET_ITEM(layer, 3));
        Py_INCREF(keys);
        if (PyList_Append(layers, layer) < 0) {
            Py_DECREF(layer);
            goto done;
        }
        Py_DECREF(layer);
    }
    /* the first state (in layer order) of least objective */
    Py_ssize_t n_end = PyList_GET_SIZE(accs), end = 0;
    if (n_end == 0) {
        result = Py_None;
        Py_INCREF(result);
        goto done;
    }
    double best = PyFloat_AsDouble(PyList_GET_ITEM(accs, 0));
    for (Py_ssize_t i = 1; i < n_end; i++) {
        double a = PyFloat_AsDouble(PyList_GET_ITEM(accs, i));
        if (a < best) best = a, end = i;
    }
    if (PyErr_Occurred()) goto done;
    ks = PyList_New(n_groups);
    pers = PyList_New(n_groups);
    states = PyList_New(n_groups);
    if (!ks || !pers || !states) goto done;
    Py_ssize_t cur = end;
    for (Py_ssize_t g = n_groups - 1; g >= 0; g--) {
        PyObject *after = PyList_GET_ITEM(layers, g + 1), *before = PyList_GET_ITEM(layers, g);
        PyObject *w = PyList_GET_ITEM(groups, g);
        Py_ssize_t n_options = PyLong_AsSsize_t(PyTuple_GET_ITEM(after, 5));
        Py_ssize_t code = PyLong_AsSsize_t(PyList_GET_ITEM(PyTuple_GET_ITEM(after, 4), cur));
        if (code == -1 && PyErr_Occurred()) goto done;
        Py_ssize_t prev_id = code / n_options, k = code % n_options;
        Py_ssize_t ri, rh, lh;
        layer_parts(before, prev_id, &ri, &rh, &lh);
        PyObject *row = PyList_GET_ITEM(PyTuple_GET_ITEM(before, 0), ri);
        PyObject *prev = PyTuple_GET_ITEM(row, 0), *prev_t = PyTuple_GET_ITEM(row, 1);
        Py_ssize_t r = none_index;
        if (prev != Py_None && prev_t != Py_None &&
            PyFloat_AS_DOUBLE(PyList_GET_ITEM(times, g)) - PyFloat_AS_DOUBLE(prev_t) < rest_s) {
            r = PyLong_AsSsize_t(prev);
            if (r == -1 && PyErr_Occurred()) goto done;
        }
        PyObject *back = PyTuple_GET_ITEM(w, 6);
        if (k >= PyTuple_GET_SIZE(back)) {
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
        PyObject *opt = PyTuple_GET_ITEM(back, k); /* (n strokes, (motion, stroke), ...) */
        if (!PyTuple_CheckExact(opt) || PyTuple_GET_SIZE(opt) < 1) {
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
        Py_ssize_t n_strokes = PyLong_AsSsize_t(PyTuple_GET_ITEM(opt, 0));
        if (n_strokes < 0) goto done_refused;
        PyObject *per = PyTuple_New(n_strokes);
        if (!per) goto done;
        for (Py_ssize_t i = 0; i < n_strokes; i++) {
            PyObject *zero = PyFloat_FromDouble(0.0);
            if (!zero) {
                Py_DECREF(per);
                goto done;
            }
            PyTuple_SET_ITEM(per, i, zero);
        }
        for (Py_ssize_t j = 1; j < PyTuple_GET_SIZE(opt); j++) {
            PyObject *pm = PyTuple_GET_ITEM(opt, j);
            if (!PyTuple_CheckExact(pm) || PyTuple_GET_SIZE(pm) != 2) {
                Py_DECREF(per);
                goto done_refused;
            }
            Py_ssize_t m = PyLong_AsSsize_t(PyTuple_GET_ITEM(pm, 0));
            Py_ssize_t i = PyLong_AsSsize_t(PyTuple_GET_ITEM(pm, 1));
            if (r < 0 || r >= n_table || i < 0 || i >= n_strokes) {
                Py_DECREF(per);
                result = Py_None;
                Py_INCREF(result);
                goto done;
            }
            PyObject *trow = PyTuple_GET_ITEM(table, r);
            if (!PyTuple_Check(trow) || m < 0 || m >= PyTuple_GET_SIZE(trow)) {
                Py_DECREF(per);
                result = Py_None;
                Py_INCREF(result);
                goto done;
            }
            PyObject *c = PyTuple_GET_ITEM(trow, m);
            Py_INCREF(c);
            Py_SETREF(PyTuple_GET_ITEM(per, i), c);
            r = m;
        }
        PyList_SET_ITEM(pers, g, per);
        PyObject *kk = PyLong_FromSsize_t(k);
        if (!kk) goto done;
        PyList_SET_ITEM(ks, g, kk);
        layer_parts(after, cur, &ri, &rh, &lh);
        PyObject *arow = PyList_GET_ITEM(PyTuple_GET_ITEM(after, 0), ri);
        PyObject *aright = PyList_GET_ITEM(PyTuple_GET_ITEM(after, 1), rh);
        PyObject *aleft = PyList_GET_ITEM(PyTuple_GET_ITEM(after, 2), lh);
        PyObject *st = PyTuple_Pack(6, PyTuple_GET_ITEM(arow, 0), PyTuple_GET_ITEM(arow, 1),
                                    PyTuple_GET_ITEM(aright, 0), PyTuple_GET_ITEM(aleft, 0),
                                    PyTuple_GET_ITEM(aright, 1), PyTuple_GET_ITEM(aleft, 1));
        if (!st) goto done;
        PyList_SET_ITEM(states, g, st);
        cur = prev_id;
    }
    result = Py_BuildValue("(OOOO)", ks, pers, states, PyList_GET_ITEM(accs, end));
    goto done;
done_refused:
    if (!PyErr_Occurred()) {
        result = Py_None;
        Py_INCREF(result);
    }
done:
    Py_XDECREF(layers);
    Py_XDECREF(accs);
    Py_XDECREF(keys);
    Py_XDECREF(ks);
    Py_XDECREF(pers);
    Py_XDECREF(states);
    Py_XDECREF(mi);
    Py_XDECREF(rs);
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
