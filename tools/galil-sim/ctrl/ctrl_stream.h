/*
 * ctrl_stream.h - DR: the data record as a stream. Every n0 servo samples
 * the controller takes its QR record (ctrl_rec.h) and queues it, one whole
 * record per datagram, for the UDP handle n1; net/ sends the queue
 * (ctrl_stream_take(), ctrl.h). No record is made while a download (DL)
 * is in progress on any handle (the reference's pause during DL; the other
 * commands it names finish between two samples here).
 *
 * It is not the record's layout (ctrl_rec.h) and not the socket.
 */
#ifndef SIM_CTRL_STREAM_H
#define SIM_CTRL_STREAM_H

#include "ctrl_int.h"

/*
 * ctrl_stream_cmd() - DR n0,n1: n0 = 0 stops the stream, else
 * CTRL_DR_MIN..CTRL_DR_MAX samples between records; n1 = handle 0..7 (A..H),
 * which must be an open UDP handle (absent: the CF handle). Events: "handle
 * C: data record every 2 samples (handle A)" when it takes effect, "handle
 * C: data record stopped: DR 0 (handle A); records made: N" when DR 0
 * stops a running stream (N since the DR that started it).
 * Return: 0, TC 6 (n0 or n1 out of range), TC 50 (no argument), TC 133
 * (n1 is not an open UDP handle), or the expression's TC.
 */
int ctrl_stream_cmd(struct ctrl_xc *x, const char *a);

/* ctrl_stream_sample() - once per servo sample, after the time advanced:
 * queue a record when one is due. */
void ctrl_stream_sample(struct ctrl *c);

/* ctrl_stream_handle_closed() - handle @h closed: a stream to it stops
 * (event "... data record stopped: handle closed; records made: N") and
 * its queued records are dropped. */
void ctrl_stream_handle_closed(struct ctrl *c, int h);

/* ctrl_stream_reset() - power cycle: the stream off (event "... data
 * record stopped: power cycle; records made: N" if it ran), the queue
 * empty. */
void ctrl_stream_reset(struct ctrl *c);

#endif /* SIM_CTRL_STREAM_H */
