#include "client/connection.h"

#include <chrono>
#include <cstdlib>

#include "client/exit_codes.h"
#include "common/secure_channel/connection_diagnosis.h"

namespace mbopt::client {

std::string ResolveServerAddress(const std::string& flag_value) {
  if (!flag_value.empty()) return flag_value;
  const char* env = std::getenv("MBOPT_SERVER");
  if (env != nullptr && env[0] != '\0') return env;
  return kDefaultServerAddress;
}

std::unique_ptr<v1::JobService::Stub> ConnectJobService(const std::string& address,
                                                        const secure_channel::ClientSecurity& security) {
  grpc::ChannelArguments args;
  // Results of big studies (many cycles) exceed the 4 MB default.
  args.SetMaxReceiveMessageSize(256 * 1024 * 1024);
  return v1::JobService::NewStub(secure_channel::CreateChannel(address, security, args));
}

RpcFailure DescribeRpcFailure(const grpc::Status& status, const std::string& address,
                              const secure_channel::ClientSecurity* security) {
  const std::string detail = status.error_message();
  switch (status.error_code()) {
    case grpc::StatusCode::UNAVAILABLE: {
      const std::string cause =
          security != nullptr ? secure_channel::DiagnoseConnectionFailure(address, *security) : "";
      if (!cause.empty()) return {"cannot connect to server at " + address + ": " + cause, kExitUnreachable};
      return {"cannot reach server at " + address + ": " + detail, kExitUnreachable};
    }
    case grpc::StatusCode::UNAUTHENTICATED:
    case grpc::StatusCode::PERMISSION_DENIED:
      return {"server at " + address + " refused: " + detail, kExitDenied};
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return {"server at " + address + " did not answer in time: " + detail, kExitUnreachable};
    case grpc::StatusCode::NOT_FOUND:
      return {detail.empty() ? "not found on server " + address : detail, kExitBadInput};
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::FAILED_PRECONDITION:
    case grpc::StatusCode::OUT_OF_RANGE:
    case grpc::StatusCode::ALREADY_EXISTS:
      return {detail, kExitBadInput};
    case grpc::StatusCode::CANCELLED:
      return {"call cancelled: " + detail, kExitInterrupted};
    default:
      return {"server at " + address + " returned an error (" +
                  std::to_string(static_cast<int>(status.error_code())) + "): " + detail,
              kExitUnreachable};
  }
}

void SetUnaryDeadline(grpc::ClientContext* context) {
  context->set_deadline(std::chrono::system_clock::now() +
                        std::chrono::seconds(kUnaryDeadlineSeconds));
}

grpc::Status GetJob(v1::JobService::Stub& job_service, const std::string& job_id, v1::GetJobResponse* response) {
  v1::JobRef ref;
  ref.set_job_id(job_id);
  grpc::ClientContext context;
  SetUnaryDeadline(&context);
  return job_service.Get(&context, ref, response);
}

}  // namespace mbopt::client
