//! The PLC's node manager: async-opcua's in-memory address space, with
//! writes and method calls handed to the PLC together with who made them
//! ([`Caller`]: the session, its user, its client's certificate).
//!
//! Written here because async-opcua's `SimpleNodeManager` gives its write
//! and method callbacks the value alone, and control authority needs to
//! know which session wrote a setpoint. Everything else (access levels,
//! type checks, reads, subscriptions) is async-opcua's.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, RwLock};

use async_trait::async_trait;
use opcua::server::address_space::AddressSpace;
use opcua::server::diagnostics::NamespaceMetadata;
use opcua::server::node_manager::memory::{
    InMemoryNodeManager, InMemoryNodeManagerBuilder, InMemoryNodeManagerImpl,
};
use opcua::server::node_manager::{
    MethodCall, NodeManagerBuilder, RequestContext, ServerContext, WriteNode,
};
use opcua::types::{AttributeId, NodeClass, NodeId, StatusCode, Variant};

use crate::control::Caller;

/// A write handler: the caller and the value written; the status to return.
pub type WriteFn = Box<dyn Fn(&Caller, &Variant) -> StatusCode + Send + Sync>;
/// A method handler: the caller and the arguments; the outputs or a status.
pub type CallFn =
    Box<dyn Fn(&Caller, &[Variant]) -> Result<Vec<Variant>, StatusCode> + Send + Sync>;
/// Whether a session is still open (it has not closed or timed out).
type AliveFn = Box<dyn Fn() -> bool + Send + Sync>;

/// The node manager's own part (see the module's docs).
pub struct ShovelNodes {
    namespace: NamespaceMetadata,
    writes: RwLock<HashMap<NodeId, WriteFn>>,
    calls: RwLock<HashMap<NodeId, CallFn>>,
    sessions: Mutex<HashMap<u32, AliveFn>>,
}

/// The manager as the server holds it.
pub type ShovelNodeManager = InMemoryNodeManager<ShovelNodes>;

/// The builder for [`ServerBuilder::with_node_manager`](opcua::server::ServerBuilder::with_node_manager).
pub fn shovel_node_manager(namespace_uri: &str) -> impl NodeManagerBuilder {
    let uri = namespace_uri.to_string();
    InMemoryNodeManagerBuilder::new(move |context: ServerContext, space: &mut AddressSpace| {
        let index = context
            .type_tree
            .write()
            .namespaces_mut()
            .add_namespace(&uri);
        space.add_namespace(&uri, index);
        ShovelNodes {
            namespace: NamespaceMetadata {
                namespace_uri: uri,
                namespace_index: index,
                ..Default::default()
            },
            writes: Default::default(),
            calls: Default::default(),
            sessions: Default::default(),
        }
    })
}

fn read<T>(l: &RwLock<T>) -> std::sync::RwLockReadGuard<'_, T> {
    l.read().unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl ShovelNodes {
    /// Hands writes of `id`'s value to `f`.
    pub fn on_write(&self, id: NodeId, f: WriteFn) {
        self.writes
            .write()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .insert(id, f);
    }

    /// Hands calls of the method `id` to `f`.
    pub fn on_call(&self, id: NodeId, f: CallFn) {
        self.calls
            .write()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .insert(id, f);
    }

    /// Whether the session `id`, once seen writing or calling, is still
    /// open (None: never seen).
    pub fn session_open(&self, id: u32) -> Option<bool> {
        let s = self.sessions.lock().unwrap_or_else(|e| e.into_inner());
        s.get(&id).map(|alive| alive())
    }

    /// Who made the request, and remembers how to tell whether its session is open.
    fn caller(&self, context: &RequestContext) -> Caller {
        let weak = Arc::downgrade(&context.session);
        self.sessions
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .entry(context.session_id)
            .or_insert_with(|| {
                Box::new(move || weak.upgrade().is_some_and(|s| s.read().is_activated()))
            });
        let s = context.session.read();
        let app = s.application_description().application_uri.to_string();
        let thumb = s
            .client_certificate()
            .map(|c| c.thumbprint().as_hex_string())
            .unwrap_or_else(|| "no certificate".into());
        Caller {
            session: context.session_id,
            user: (!context.token.is_anonymous()).then(|| context.token.0.clone()),
            client: format!("{app} [{thumb}]"),
        }
    }
}

#[async_trait]
impl InMemoryNodeManagerImpl for ShovelNodes {
    async fn init(&self, _address_space: &mut AddressSpace, _context: ServerContext) {}

    fn name(&self) -> &str {
        "shovel"
    }

    fn namespaces(&self) -> Vec<NamespaceMetadata> {
        vec![self.namespace.clone()]
    }

    async fn write(
        &self,
        context: &RequestContext,
        address_space: &opcua::sync::RwLock<AddressSpace>,
        nodes_to_write: &mut [&mut WriteNode],
    ) -> Result<(), StatusCode> {
        let caller = self.caller(context);
        let mut space = address_space.write();
        let type_tree = context.type_tree.read();
        let handlers = read(&self.writes);
        for w in nodes_to_write {
            let status = match space.validate_node_write(context, w.value(), &*type_tree) {
                Err(e) => e,
                Ok(node)
                    if node.node_class() != NodeClass::Variable
                        || w.value().attribute_id != AttributeId::Value =>
                {
                    StatusCode::BadNotWritable
                }
                Ok(node) => match (
                    handlers.get(node.as_node().node_id()),
                    &w.value().value.value,
                ) {
                    (Some(h), Some(v)) => h(&caller, v),
                    (Some(_), None) => StatusCode::BadTypeMismatch,
                    (None, _) => StatusCode::BadNotWritable,
                },
            };
            w.set_status(status);
        }
        Ok(())
    }

    async fn call(
        &self,
        context: &RequestContext,
        _address_space: &opcua::sync::RwLock<AddressSpace>,
        methods_to_call: &mut [&mut &mut MethodCall],
    ) -> Result<(), StatusCode> {
        let caller = self.caller(context);
        let handlers = read(&self.calls);
        for m in methods_to_call {
            match handlers.get(m.method_id()) {
                Some(h) => match h(&caller, m.arguments()) {
                    Ok(out) => {
                        m.set_outputs(out);
                        m.set_status(StatusCode::Good);
                    }
                    Err(e) => m.set_status(e),
                },
                None => m.set_status(StatusCode::BadMethodInvalid),
            }
        }
        Ok(())
    }
}
