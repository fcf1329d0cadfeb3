/*
 * re_relay_readback.c - confirming a switch, and the Devantech read-back:
 * the state query (0x5B) and its answers, waited for when the relay is
 * switched, one step per check and never waiting in re_relay_check() (the
 * decisions: re_relay.c's header).
 */
#include <stdbool.h>
#include <stdint.h>

#include "base_clock.h"
#include "gl_err.h"
#include "re_relay_int.h"

#define DEVANTECH_QUERY 0x5B /* answer: bit n-1 set = relay n on */
#define RB_READ_MAX	16   /* answer bytes read at once by a check */

/* The state query goes out (or is due): count the answer owed. */
static void rb_sent_one(struct re_relay *r)
{
	if (!r->rb_due++)
		r->rb_sent_ns = base_now_ns();
}

/* Does a state-query answer show the channel @on? */
static bool rb_shows(const struct re_relay *r, uint8_t b, bool on)
{
	return ((b >> (r->cfg.channel - 1)) & 1) == on;
}

/* The read-back of @what had no answer by its deadline: the answers stay
 * due; a query the driver never took is dropped (a lone byte). */
static int rb_timeout(struct re_relay *r, const char *what, int ms)
{
	r->rb_discard = true;
	if (r->out_done < r->out_len) {
		re_relay_out_set(r, NULL, 0);
		return re_relay_set_err(
		    r, GL_ERR_TIMEOUT,
		    "%s not confirmed: the state query (0x5B) was "
		    "not accepted by the driver within %d ms",
		    what, ms);
	}
	return re_relay_set_err(
	    r, GL_ERR_TIMEOUT,
	    "%s not confirmed: no answer to the state query (0x5B) "
	    "within %d ms",
	    what, ms);
}

/*
 * Devantech read-back until @deadline: send the state query and read the
 * answers. Answers still due to queries of re_relay_check() arrive first:
 * one showing the channel @on confirms as well (only this call switches the
 * relay, so a state seen after the write started still holds); one showing
 * the other state is judged only when it must be the answer to this
 * query. On a timeout the answers stay due, timed from the oldest query,
 * so that re_relay_check() reports a silent board after
 * readback_timeout_ms.
 */
static int readback_wait(struct re_relay *r, const char *what, bool on,
			 int64_t deadline, int ms)
{
	static const uint8_t query = DEVANTECH_QUERY;
	int skip = r->rb_due, n = 0;
	uint8_t b = 0;

	if (!skip && re_relay_drop_input(r))
		return GL_ERR_SYS;
	re_relay_out_set(r, &query, 1);
	for (;;) {
		if (re_relay_out_push(r))
			return GL_ERR_SYS;
		if (r->out == &query && r->out_done) {
			rb_sent_one(r);
			re_relay_out_set(r, NULL, 0);
		}
		if (!r->out)
			n = r->ops->read(&r->io, &b, 1, r->err, sizeof(r->err));
		if (n < 0)
			return GL_ERR_SYS;
		if (n == 1 && r->rb_due)
			r->rb_due--;
		if (n == 1 && rb_shows(r, b, on)) {
			r->rb_due = 0; /* the rest, if any, agrees */
			r->rb_flush = skip > 0;
			return GL_OK;
		}
		if (n == 1 && !skip--)
			return re_relay_set_err(
			    r, GL_ERR_RELAY,
			    "%s not confirmed: read-back shows "
			    "channel %d %s",
			    what, r->cfg.channel, on ? "off" : "on");
		if (n == 1)
			continue;
		if (base_now_ns() >= deadline)
			break;
		re_relay_nap(deadline);
	}
	return rb_timeout(r, what, ms);
}

/* After writing @what: sent, and read back where the board can. */
int re_relay_confirm(struct re_relay *r, const char *what, bool on,
		     int64_t deadline, int ms)
{
	int rc = re_relay_out_wait(r, what, deadline, ms);

	if (rc == GL_OK && r->cfg.readback)
		rc = readback_wait(r, what, on, deadline, ms);
	return rc;
}

/* Between two queries of re_relay_check(): query_ms, or less so that two
 * fit in readback_timeout_ms. */
static int64_t rb_interval_ns(const struct re_relay *r)
{
	int ms = r->cfg.readback_timeout_ms / 2;

	if (ms > r->cfg.query_ms)
		ms = r->cfg.query_ms;
	return ms > 0 ? (int64_t)ms * BASE_NS_PER_MS : 0;
}

/* The state query of re_relay_check(), when one is due (query_ms). */
static int rb_query(struct re_relay *r)
{
	static const uint8_t query = DEVANTECH_QUERY;
	int n;

	if (base_now_ns() < r->rb_next_ns)
		return GL_OK;
	r->rb_next_ns = base_now_ns() + rb_interval_ns(r);
	if (r->rb_flush && re_relay_drop_input(r))
		return GL_ERR_RELAY;
	r->rb_flush = false;
	n = r->ops->write(&r->io, &query, 1, r->err, sizeof(r->err));
	if (n < 0)
		return GL_ERR_RELAY;
	if (n == 0)
		return re_relay_set_err(r, GL_ERR_RELAY,
					"the state query (0x5B) was not "
					"accepted: output buffer full");
	rb_sent_one(r);
	r->rb_discard = false;
	return GL_OK;
}

/* One answer byte @b: the last one due is judged against the state last
 * confirmed (not while UNKNOWN, not when it predates a write); a byte
 * nobody awaits is dropped. */
static int rb_answer(struct re_relay *r, uint8_t b)
{
	bool on;

	if (!r->rb_due)
		return GL_OK;
	if (--r->rb_due || r->rb_discard || r->state == RE_RELAY_UNKNOWN)
		return GL_OK; /* an older answer, or nothing to compare */
	on = r->state == RE_RELAY_ON;
	if (!rb_shows(r, b, on))
		return re_relay_set_err(
		    r, GL_ERR_RELAY,
		    "read-back shows channel %d %s, expected %s",
		    r->cfg.channel, on ? "off" : "on", on ? "on" : "off");
	return GL_OK;
}

/*
 * Devantech read-back: one step per check, never waiting. The board must
 * answer within readback_timeout_ms whatever the state. What has arrived
 * is read at once (up to RB_READ_MAX bytes): the input is then empty for
 * the next query, so no read to drop stale bytes is needed before it
 * unless answers may be in flight that nobody awaits (rb_flush). Nothing
 * is sent while a message is half written.
 */
int re_relay_readback_step(struct re_relay *r)
{
	uint8_t buf[RB_READ_MAX];
	int n, rc;

	if (!r->cfg.readback || r->out_done < r->out_len)
		return GL_OK;
	if (!r->rb_due)
		return rb_query(r);
	n = r->ops->read(&r->io, buf, sizeof(buf), r->err, sizeof(r->err));
	if (n < 0)
		return GL_ERR_RELAY;
	if (n == 0) {
		if ((base_now_ns() - r->rb_sent_ns) / BASE_NS_PER_MS <=
		    r->cfg.readback_timeout_ms)
			return GL_OK;
		return re_relay_set_err(r, GL_ERR_RELAY,
					"no answer to the state query "
					"(0x5B) within %d ms",
					r->cfg.readback_timeout_ms);
	}
	for (int i = 0; i < n; i++)
		if ((rc = rb_answer(r, buf[i])) != GL_OK)
			return rc;
	if (n == (int)sizeof(buf))
		r->rb_flush = true; /* more may be waiting */
	return GL_OK;
}
