/*
 * rtapi_list.h - circular doubly-linked lists threaded through the
 * structures they link (a struct rtapi_list_head member in each).
 */
#ifndef RTAPI_LIST_H
#define RTAPI_LIST_H

#include <stddef.h>

#include "rtapi.h"

RTAPI_BEGIN_DECLS

struct rtapi_list_head {
    struct rtapi_list_head *next, *prev;
};

/* an empty list points at itself */
static inline void RTAPI_INIT_LIST_HEAD(struct rtapi_list_head *list)
{
    list->next = list;
    list->prev = list;
}

static inline void rtapi_list_add(struct rtapi_list_head *item,
                                  struct rtapi_list_head *head)
{
    struct rtapi_list_head *first = head->next;
    item->next = first;
    item->prev = head;
    first->prev = item;
    head->next = item;
}

static inline void rtapi_list_add_tail(struct rtapi_list_head *item,
                                       struct rtapi_list_head *head)
{
    struct rtapi_list_head *last = head->prev;
    item->next = head;
    item->prev = last;
    last->next = item;
    head->prev = item;
}

static inline void rtapi_list_del(struct rtapi_list_head *item)
{
    item->prev->next = item->next;
    item->next->prev = item->prev;
    item->next = NULL;
    item->prev = NULL;
}

#define rtapi_list_for_each(pos, head)                                    \
    for ((pos) = (head)->next; (pos) != (head); (pos) = (pos)->next)

/* the structure of type that holds member at ptr */
#define rtapi_container_of(ptr, type, member)                             \
    ((type *)((char *)(ptr) - offsetof(type, member)))
#define rtapi_list_entry(ptr, type, member)                               \
    rtapi_container_of(ptr, type, member)

RTAPI_END_DECLS

#endif
