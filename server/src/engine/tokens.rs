//! Registration tokens: what makes a registration safe to retry.
//!
//! A client puts a token of its choosing (random, not 0) into a
//! registration ([`gjkd_proto::AdminRequest::token`]). The server remembers,
//! for each owner, the tokens of its last [`TOKENS_PER_OWNER`]
//! registrations with the ids they got, in the same database transaction
//! as the object ([`crate::persist::database`]), so a retry of a registration whose
//! reply was lost (a timeout, or a server killed between the commit and
//! the reply) gets the id of the object that was stored instead of a
//! second object. A token is forgotten with its object (a retry after a
//! removal registers anew) or when the owner has registered
//! [`TOKENS_PER_OWNER`] more objects since.

use std::collections::{HashMap, VecDeque};

/// Most tokens remembered per owner: a `gjkd-client` `Client` retries only
/// the registration in flight, so a few would do; this leaves room for a
/// client that pipelines requests.
pub const TOKENS_PER_OWNER: usize = 64;

/// A remembered token: its owner (the iceoryx2 node id of the client) and
/// the token.
pub type TokenKey = (u128, u64);

/// The tokens remembered, in memory (a copy of the database's table).
#[derive(Debug, Default)]
pub struct Tokens {
    ids: HashMap<TokenKey, u64>,
    keys: HashMap<u64, TokenKey>,
    /// Each owner's tokens, oldest first.
    by_owner: HashMap<u128, VecDeque<u64>>,
}

impl Tokens {
    /// The tokens of `entries` (as read from the database) whose object is
    /// `known`; an owner's are taken in id order, which is registration
    /// order, so the oldest is pushed out first as before.
    pub fn load(mut entries: Vec<(TokenKey, u64)>, known: impl Fn(u64) -> bool) -> Self {
        entries.sort_unstable_by_key(|&(_, id)| id);
        let mut tokens = Tokens::default();
        for (key, id) in entries {
            if known(id) && !tokens.ids.contains_key(&key) {
                tokens.remember(key, id);
            }
        }
        tokens
    }

    /// Number of tokens remembered.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// Whether none is.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The object registered with `key`, if remembered.
    pub fn find(&self, key: TokenKey) -> Option<u64> {
        self.ids.get(&key).copied()
    }

    /// The token of object `id`, if remembered.
    pub fn key_of(&self, id: u64) -> Option<TokenKey> {
        self.keys.get(&id).copied()
    }

    /// The token that remembering one more of `owner`'s pushes out.
    pub fn pushed_out_by_next(&self, owner: u128) -> Option<TokenKey> {
        let queue = self.by_owner.get(&owner)?;
        (queue.len() >= TOKENS_PER_OWNER)
            .then(|| queue.front().map(|&t| (owner, t)))
            .flatten()
    }

    /// Remembers that `key` registered `id`, forgetting the owner's oldest
    /// token beyond [`TOKENS_PER_OWNER`].
    pub fn remember(&mut self, key: TokenKey, id: u64) {
        if let Some(old) = self.pushed_out_by_next(key.0)
            && let Some(old_id) = self.ids.remove(&old)
        {
            self.keys.remove(&old_id);
            if let Some(queue) = self.by_owner.get_mut(&key.0) {
                queue.pop_front();
            }
        }
        self.ids.insert(key, id);
        self.keys.insert(id, key);
        self.by_owner.entry(key.0).or_default().push_back(key.1);
    }

    /// Forgets the token of object `id` (removed).
    pub fn forget_object(&mut self, id: u64) {
        let Some(key) = self.keys.remove(&id) else {
            return;
        };
        self.ids.remove(&key);
        if let Some(queue) = self.by_owner.get_mut(&key.0) {
            queue.retain(|&t| t != key.1);
            if queue.is_empty() {
                self.by_owner.remove(&key.0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_owner_keeps_its_last_tokens_and_removals_forget_theirs() {
        let mut t = Tokens::default();
        for i in 0..TOKENS_PER_OWNER as u64 {
            assert_eq!(t.pushed_out_by_next(7), None);
            t.remember((7, 100 + i), i);
        }
        t.remember((8, 100), 1000);
        assert_eq!(t.pushed_out_by_next(7), Some((7, 100)));
        t.remember((7, 1), 500);
        assert_eq!(t.find((7, 100)), None, "the oldest is pushed out");
        assert_eq!(t.key_of(0), None);
        assert_eq!(t.find((7, 101)), Some(1));
        assert_eq!(t.find((7, 1)), Some(500));
        assert_eq!(t.find((8, 100)), Some(1000), "owners do not share tokens");
        assert_eq!(t.len(), TOKENS_PER_OWNER + 1);
        t.forget_object(500);
        assert_eq!(t.find((7, 1)), None);
        assert_eq!(t.pushed_out_by_next(7), None);
        // Reloaded: unknown objects dropped, order by id.
        let back = Tokens::load(vec![((7, 3), 30), ((7, 2), 20), ((9, 1), 99)], |id| {
            id != 99
        });
        assert_eq!((back.find((7, 2)), back.find((7, 3))), (Some(20), Some(30)));
        assert_eq!(back.find((9, 1)), None);
    }
}
