//! `object_store` behind synchronous calls: one small Tokio runtime for the process, one
//! store per bucket (credentials and endpoint from the standard `AWS_*` variables:
//! `AWS_ENDPOINT_URL`, `AWS_ACCESS_KEY_ID`, `AWS_SECRET_ACCESS_KEY`, `AWS_REGION`,
//! `AWS_ALLOW_HTTP=true` for a local server).

use std::collections::HashMap;
use std::io;
use std::ops::Range;
use std::sync::{Arc, Mutex, OnceLock};

use futures::TryStreamExt;
use object_store::aws::AmazonS3Builder;
use object_store::path::Path as ObjectPath;
use object_store::{ObjectStore, ObjectStoreExt, PutPayload};
use xxhash_rust::xxh3::Xxh3;

use super::{count_fetched, split_url};

/// The process's runtime for store requests (an error when the OS refuses its thread).
fn runtime() -> io::Result<&'static tokio::runtime::Runtime> {
    static RT: OnceLock<Result<tokio::runtime::Runtime, String>> = OnceLock::new();
    RT.get_or_init(|| {
        tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .thread_name("object-store")
            .enable_all()
            .build()
            .map_err(|e| format!("cannot start the object-store runtime: {e}"))
    })
    .as_ref()
    .map_err(|e| io::Error::other(e.clone()))
}

/// The store of `url`'s bucket (built once per bucket) and the object's key.
fn store_of(url: &str) -> io::Result<(Arc<dyn ObjectStore>, ObjectPath)> {
    static STORES: OnceLock<Mutex<HashMap<String, Arc<dyn ObjectStore>>>> = OnceLock::new();
    let (bucket, key) = split_url(url)?;
    let mut stores = STORES
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let store = match stores.get(&bucket) {
        Some(s) => s.clone(),
        None => {
            let built = AmazonS3Builder::from_env()
                .with_url(bucket.clone())
                .build()
                .map_err(|e| store_error(url, e))?;
            let s: Arc<dyn ObjectStore> = Arc::new(built);
            stores.insert(bucket, s.clone());
            s
        }
    };
    let path = ObjectPath::parse(&key).map_err(|e| store_error(url, e))?;
    Ok((store, path))
}

fn store_error(url: &str, e: impl std::fmt::Display) -> io::Error {
    io::Error::other(format!("{url}: {e}"))
}

fn is_not_found(e: &object_store::Error) -> bool {
    matches!(e, object_store::Error::NotFound { .. })
}

/// An object opened for range reads: its size and ETag from one HEAD request.
#[derive(Debug)]
pub struct RemoteObject {
    url: String,
    store: Arc<dyn ObjectStore>,
    path: ObjectPath,
    pub size: u64,
    pub e_tag: Option<String>,
}

impl RemoteObject {
    pub fn open(url: &str) -> io::Result<RemoteObject> {
        let (store, path) = store_of(url)?;
        let meta = runtime()?
            .block_on(store.head(&path))
            .map_err(|e| match is_not_found(&e) {
                true => io::Error::new(io::ErrorKind::NotFound, format!("{url}: no such object")),
                false => store_error(url, e),
            })?;
        Ok(RemoteObject {
            url: url.to_string(),
            store,
            path,
            size: meta.size,
            e_tag: meta.e_tag,
        })
    }

    /// `len` bytes at `offset`, with one range request (the caller keeps it inside the object).
    pub fn read_at(&self, offset: u64, len: u64) -> io::Result<Vec<u8>> {
        if len == 0 {
            return Ok(Vec::new());
        }
        let range: Range<u64> = offset..offset + len;
        let bytes = runtime()?
            .block_on(self.store.get_range(&self.path, range))
            .map_err(|e| store_error(&self.url, e))?;
        count_fetched(bytes.len() as u64);
        if bytes.len() as u64 != len {
            return Err(io::Error::new(
                io::ErrorKind::UnexpectedEof,
                format!(
                    "{}: asked for {len} bytes at {offset}, the store sent {}",
                    self.url,
                    bytes.len()
                ),
            ));
        }
        Ok(bytes.to_vec())
    }

    /// The object's content key: its ETag and size (an S3 ETag changes with the bytes), or,
    /// from a store that gives no ETag, the hash of its bytes (read once, in 8 MiB ranges).
    pub fn content_hash(&self) -> io::Result<u128> {
        let mut h = Xxh3::new();
        match &self.e_tag {
            Some(tag) => {
                h.update(b"etag\0");
                h.update(tag.as_bytes());
                h.update(&self.size.to_le_bytes());
            }
            None => {
                let step = 8 << 20;
                let mut at = 0;
                while at < self.size {
                    let n = step.min(self.size - at);
                    h.update(&self.read_at(at, n)?);
                    at += n;
                }
            }
        }
        Ok(h.digest128())
    }
}

/// The whole object at `url`, or `None` when there is none.
pub fn get(url: &str) -> io::Result<Option<Vec<u8>>> {
    let (store, path) = store_of(url)?;
    runtime()?.block_on(async {
        match store.get(&path).await {
            Ok(r) => {
                let bytes = r.bytes().await.map_err(|e| store_error(url, e))?;
                count_fetched(bytes.len() as u64);
                Ok(Some(bytes.to_vec()))
            }
            Err(e) if is_not_found(&e) => Ok(None),
            Err(e) => Err(store_error(url, e)),
        }
    })
}

/// Write `bytes` to `url` with one put (the object appears whole or not at all).
pub fn put(url: &str, bytes: Vec<u8>) -> io::Result<()> {
    let (store, path) = store_of(url)?;
    runtime()?
        .block_on(store.put(&path, PutPayload::from(bytes)))
        .map(|_| ())
        .map_err(|e| store_error(url, e))
}

/// Every object below the URL prefix `prefix` (a "folder" when it ends with `/`), sorted.
pub fn list(prefix: &str) -> io::Result<Vec<String>> {
    let (bucket, key) = split_url(prefix)?;
    let (store, _) = store_of(&bucket)?;
    let listed =
        ObjectPath::parse(key.trim_end_matches('/')).map_err(|e| store_error(prefix, e))?;
    let metas: Vec<object_store::ObjectMeta> = runtime()?
        .block_on(store.list(Some(&listed)).try_collect())
        .map_err(|e| store_error(prefix, e))?;
    let mut out: Vec<String> = metas
        .into_iter()
        .map(|m| format!("{bucket}/{}", m.location))
        .filter(|u| u.starts_with(prefix))
        .collect();
    out.sort();
    Ok(out)
}

/// Every object URL below `pattern`'s fixed prefix that matches the glob `pattern`, sorted.
pub fn list_matching(pattern: &str) -> io::Result<Vec<String>> {
    let glob = glob::Pattern::new(pattern)
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, format!("{pattern}: {e}")))?;
    let options = glob::MatchOptions {
        require_literal_separator: true,
        ..Default::default()
    };
    Ok(list(super::glob_prefix(pattern))?
        .into_iter()
        .filter(|u| glob.matches_with(u, options))
        .collect())
}
